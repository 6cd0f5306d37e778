"""Start a simulation from a world name and options: checks, the node, the summary."""

from __future__ import annotations

import math
import sys
from typing import TYPE_CHECKING

from rosl.sim.errors import SimError

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.sim.options import SimOptions
    from rosl.sim.report import SimReport


def _positive(value: float) -> bool:
    """Greater than 0 and finite (NaN is neither)."""
    return math.isfinite(value) and value > 0


def check_options(options: SimOptions) -> None:
    """Refuse options that cannot work, before anything starts.

    Raises:
        SimError: naming the option and what it needs.
    """
    if not _positive(options.real_time_factor):
        raise SimError(
            "--real-time-factor must be greater than 0 (and finite), "
            f"not {options.real_time_factor:g} (use --fast to run as fast as the controllers allow)"
        )
    if options.duration is not None and not _positive(options.duration):
        raise SimError(
            f"--duration must be greater than 0 seconds (and finite), not {options.duration:g}"
        )
    if not _positive(options.clock_rate):
        raise SimError(
            f"--clock-rate must be greater than 0 Hz (and finite), not {options.clock_rate:g} "
            "(a rate at or above the physics rate publishes /clock every step)"
        )
    if not _positive(options.lockstep_timeout):
        raise SimError(
            "--lockstep-timeout must be greater than 0 seconds (and finite), "
            f"not {options.lockstep_timeout:g}"
        )
    if options.render is not None and options.render.suffix.lower() not in (".svg", ".png"):
        raise SimError(f"--render {options.render}: the picture must be a .svg or .png file")
    record = options.record
    if record is not None and record.exists() and (not record.is_dir() or any(record.iterdir())):
        raise SimError(f"--record {record}: the folder already exists and is not empty")


def simulate(
    world_name: str | Path,
    options: SimOptions,
    *,
    seed: int | None = None,
    ros_args: list[str] | None = None,
    domain: int | str | None = None,
) -> SimReport:
    """Load a world, run it as node ``sim`` until done, and return the report.

    Raises:
        WorldFileError: the world or a robot file is wrong (file:line).
        SimError: the options cannot work.
        LockstepStall: a controller stopped answering and ``on_stall`` is stop.
    """
    import rosl
    from rosl.sim.sim_node import SimNode
    from rosl.sim.simulation import Simulation
    from rosl.sim.worldfile import load_world, resolve_world

    check_options(options)
    world = load_world(resolve_world(str(world_name)))
    rosl.init(ros_args or [], domain_id=domain)
    try:
        node = rosl.Node("sim")
        try:
            sim = Simulation(world, seed=seed)
            return SimNode(sim, node, options).run()
        finally:
            node.destroy_node()
    finally:
        rosl.try_shutdown()


def run_sim(argv: list[str]) -> int:
    """``sim WORLD [options] [--ros-args ...]``: the rosl_sim package's executable."""
    from rosl.errors import RoslError
    from rosl.node.ros_args import split_ros_args
    from rosl.sim.options import parse_arguments

    _, user = split_ros_args(argv)
    world, options, seed = parse_arguments(user)
    try:
        report = simulate(world, options, seed=seed, ros_args=argv)
    except RoslError as err:
        print(f"sim: {err}", file=sys.stderr, flush=True)
        return 1
    print("\n".join(report.lines()), flush=True)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``rosl run rosl_sim sim WORLD ...`` (and launch files' Node actions)."""
    return run_sim(sys.argv[1:] if argv is None else argv)
