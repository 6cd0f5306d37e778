"""How to run a simulation: ``rosl sim``'s options, and the executable's argument parser."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

CLOCK_RATE = 10.0  # Hz of sim time: gazebo_ros's /clock publish_rate default (it counts wall time)


@dataclass(slots=True)
class SimOptions:
    """How to run a simulation (``rosl sim``'s options)."""

    real_time_factor: float = 1.0
    fast: bool = False
    duration: float | None = None
    record: Path | None = None
    render: Path | None = None
    headless: bool = False
    wait_for: list[str] = field(default_factory=list)
    startup_timeout: float = 10.0
    lockstep_timeout: float = 5.0
    on_stall: str = "continue"
    clock_rate: float = CLOCK_RATE


def parse_arguments(argv: list[str]) -> tuple[Path, SimOptions, int | None]:
    """``sim WORLD [options]`` as the executable of package rosl_sim takes them."""
    import argparse

    parser = argparse.ArgumentParser(prog="sim", description="rosl's 2D simulator as a node")
    parser.add_argument("world")
    parser.add_argument("--real-time-factor", type=float, default=1.0)
    parser.add_argument("--fast", action="store_true")
    parser.add_argument("--duration", type=float)
    parser.add_argument("--seed", type=int)
    parser.add_argument("--record", type=Path)
    parser.add_argument("--render", type=Path)
    parser.add_argument("--headless", action="store_true")
    parser.add_argument("--wait-for", action="append", default=[])
    parser.add_argument("--startup-timeout", type=float, default=10.0)
    parser.add_argument("--lockstep-timeout", type=float, default=5.0)
    parser.add_argument("--on-stall", choices=["continue", "stop"], default="continue")
    parser.add_argument("--clock-rate", type=float, default=CLOCK_RATE)
    args = parser.parse_args(argv)
    options = SimOptions(
        real_time_factor=args.real_time_factor,
        fast=args.fast,
        duration=args.duration,
        record=args.record,
        render=args.render,
        headless=args.headless,
        wait_for=args.wait_for,
        startup_timeout=args.startup_timeout,
        lockstep_timeout=args.lockstep_timeout,
        on_stall=args.on_stall,
        clock_rate=args.clock_rate,
    )
    return Path(args.world), options, args.seed
