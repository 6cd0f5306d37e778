"""``rosl bridge foxglove``: serve the live bus to Foxglove (ROS 2's foxglove_bridge)."""

from __future__ import annotations

import signal
from typing import Any

import click

from rosl.cli import render
from rosl.cli.options import domain_option


@click.group("bridge")
def command() -> None:
    """Bridges from the bus to other tools' live views."""


@command.command("foxglove")
@click.option(
    "--port",
    type=click.IntRange(0, 65535),
    default=8765,
    show_default=True,
    help="WebSocket port (0: any free port, printed at start)",
)
@click.option(
    "--address",
    default="127.0.0.1",
    show_default=True,
    help="Address to listen on (0.0.0.0: every interface, reachable from other machines)",
)
@click.option(
    "--topics",
    "topics",
    default=None,
    metavar="REGEX",
    help="Advertise only topics whose whole name matches (foxglove_bridge's topic_whitelist)",
)
@domain_option
def foxglove(port: int, address: str, topics: str | None, domain_id: int | None) -> None:
    """A Foxglove WebSocket server: topics, services, parameters and sim time, live."""
    from rosl.introspection.foxglove_bridge import NODE, BridgeOptions, FoxgloveBridge

    bridge = FoxgloveBridge(BridgeOptions(port, address, topics, domain_id), log=render.warn)

    def request_stop(signum: int, frame: Any) -> None:
        bridge.stop()

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, request_stop)
    url = bridge.start()
    try:
        render.lines([f"[INFO] [{NODE}]: Foxglove WebSocket server listening on {url}"])
        bridge.run(lambda: False)
    finally:
        bridge.close()
