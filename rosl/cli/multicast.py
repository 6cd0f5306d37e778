"""``rosl multicast send|receive``: ROS 2's one-datagram multicast check (225.0.0.1:49150)."""

from __future__ import annotations

import click

from rosl.bus import probe
from rosl.cli import render

group_option = click.option(
    "--group", default=probe.DEFAULT_GROUP, show_default=True, help="The multicast group address"
)
port_option = click.option(
    "--port",
    type=click.IntRange(1, 65535),
    default=probe.DEFAULT_PORT,
    show_default=True,
    help="The multicast port",
)


@click.group("multicast")
def command() -> None:
    """Various multicast related sub-commands (on loopback unless ROSL_INTERFACE names one)."""


@command.command("send")
@group_option
@port_option
@click.option(
    "--ttl",
    type=click.IntRange(0, 255),
    default=None,
    help="The multicast TTL  [default: 0 on loopback, 1 on ROSL_INTERFACE]",
)
def send(group: str, port: int, ttl: int | None) -> None:
    """Send a single UDP multicast packet."""
    scope = probe.scope_from_env(ttl)
    probe.check_group(group)
    render.lines(["Sending one UDP multicast datagram..."])
    probe.send(group=group, port=port, scope=scope)


@command.command("receive")
@group_option
@port_option
@click.option(
    "--timeout",
    type=click.FloatRange(min=0.0),
    default=None,
    help="Fail if nothing arrives within this many seconds  [default: wait until Ctrl-C]",
)
def receive(group: str, port: int, timeout: float | None) -> None:
    """Receive a single UDP multicast packet."""
    with probe.Listener(group=group, port=port, scope=probe.scope_from_env()) as listener:
        render.lines(["Waiting for UDP multicast datagram..."])
        heard = listener.receive(timeout)
    text = heard.data.decode("utf-8", "replace")
    render.lines([f"Received from {heard.host}:{heard.port}: '{text}'"])
