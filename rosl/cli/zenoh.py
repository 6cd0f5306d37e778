"""``rosl zenoh router``: a Zenoh router for rosl and ROS 2's rmw_zenoh nodes (as rmw_zenohd)."""

from __future__ import annotations

import click

from rosl.bus import zenoh_config
from rosl.cli import render


@click.group("zenoh")
def command() -> None:
    """Zenoh related sub-commands (ROSL_TRANSPORT=zenoh, ROS 2's rmw_zenoh)."""


@command.command("router")
@click.option(
    "--listen",
    default=None,
    help=f"Endpoint to listen on (port 0: one the system picks, printed)  [default: "
    f"{zenoh_config.ROUTER_LISTEN}, or ZENOH_ROUTER_CONFIG_URI's]",
)
def router(listen: str | None) -> None:
    """Run a Zenoh router until Ctrl-C (what rmw_zenohd is to ROS 2)."""
    session = zenoh_config.open_session(zenoh_config.router_config(listen))
    where = zenoh_config.listening_on(session) or listen or zenoh_config.router_listen_text()
    render.lines([f"Zenoh router {session.info.zid()} listening on {where}"])
    zenoh_config.serve_forever(session)
