"""``rosl sim WORLD``: run a world (paced, or lock-step with --fast), record it, draw it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from rosl.cli import render
from rosl.cli.companion import companion_options
from rosl.cli.options import domain_option
from rosl.sim.options import CLOCK_RATE


@click.command("sim")
@click.argument("world")
@click.option(
    "--real-time-factor",
    type=float,
    default=1.0,
    show_default=True,
    help="Pace sim time at this multiple of wall time",
)
@click.option(
    "--fast",
    is_flag=True,
    help="Lock-step: as fast as the subscribed controllers allow, same result every run",
)
@click.option("--duration", type=float, default=None, help="Stop after this many sim seconds")
@click.option("--seed", type=int, default=None, help="Sensor noise seed (default: the world's)")
@click.option(
    "--record",
    "record",
    is_flag=False,
    flag_value="",
    default=None,
    metavar="[DIR]",
    help="Record the bus with sim-time stamps into a rosbag2 folder",
)
@click.option(
    "--render",
    "picture",
    type=click.Path(path_type=Path),
    default=None,
    help="Draw the world, the paths and the last scan to FILE.svg or FILE.png at the end",
)
@click.option("--headless", is_flag=True, help="No live status line (rosl never opens a window)")
@click.option(
    "--wait-for",
    multiple=True,
    metavar="NODE",
    help="Lock-step: start when this node is up (repeatable; default: a cmd_vel publisher)",
)
@click.option(
    "--startup-timeout",
    type=float,
    default=10.0,
    show_default=True,
    help="Lock-step: seconds to wait for the controllers before starting anyway",
)
@click.option(
    "--lockstep-timeout",
    type=float,
    default=5.0,
    show_default=True,
    help="Lock-step: seconds to wait for a controller's answer before reporting it",
)
@click.option(
    "--on-stall",
    type=click.Choice(["continue", "stop"]),
    default="continue",
    show_default=True,
    help="Lock-step: what to do when a controller stops answering",
)
@click.option(
    "--clock-rate",
    type=float,
    default=CLOCK_RATE,
    show_default=True,
    metavar="HZ",
    help="Publish /clock this often in sim time, and with every step's sensor data",
)
@companion_options
@domain_option
def command(world: str, **options: Any) -> None:
    """Simulate a world: `rosl sim turtlebot3_world` (shipped worlds by name, or a file)."""
    from rosl.cli.companion import companions

    serve = options["serve_port"] if options["serve"] else None
    bridge = options["bridge_port"] if options["bridge"] else None
    with companions(serve=serve, bridge=bridge, domain=options["domain_id"]):
        _simulate(world, options)


def _simulate(world: str, options: dict[str, Any]) -> None:
    from rosl.sim.options import SimOptions
    from rosl.sim.runner import simulate

    record = options["record"]
    if record == "":
        import time

        record = time.strftime("rosbag2_%Y_%m_%d-%H_%M_%S")
    sim_options = SimOptions(
        real_time_factor=options["real_time_factor"], fast=options["fast"],
        duration=options["duration"], record=Path(record) if record else None,
        render=options["picture"], headless=options["headless"],
        wait_for=list(options["wait_for"]), startup_timeout=options["startup_timeout"],
        lockstep_timeout=options["lockstep_timeout"], on_stall=options["on_stall"],
        clock_rate=options["clock_rate"],
    )  # fmt: skip
    report = simulate(world, sim_options, seed=options["seed"], domain=options["domain_id"])
    render.lines(report.lines())
    from rosl.node.context import default_context

    default_context.signalled = None  # Ctrl-C is how a paced simulation ends: a clean stop, 0
