"""``rosl daemon start|stop|status``: rosl has no daemon, so each says so in one line, exit 0.

Scripts written for ROS 2 often run ``ros2 daemon stop`` (after changing the domain or the
RMW) or ``ros2 daemon start``; with rosl they keep working: every command asks the live graph,
so there is nothing to start, stop or go stale.
"""

from __future__ import annotations

import click

from rosl.cli import render

WHY = "rosl needs none: each command asks the live graph"


@click.group("daemon")
def command() -> None:
    """Various daemon related sub-commands (rosl has no daemon: these say so and exit 0)."""


@command.command("start")
@click.option("--debug", is_flag=True, help="Accepted for ROS 2 scripts; there is nothing to debug")
def start(debug: bool) -> None:
    """Start the daemon if it isn't running (rosl has none to start)."""
    render.lines([f"There is no daemon to start ({WHY})"])


@command.command("stop")
def stop() -> None:
    """Stop the daemon if it is running (rosl has none to stop)."""
    render.lines([f"There is no daemon to stop ({WHY})"])


@command.command("status")
def status() -> None:
    """Output the status of the daemon (never running: rosl needs none)."""
    render.lines([f"The daemon is not running ({WHY})"])
