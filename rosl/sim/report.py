"""What a simulation run did: per robot distance, closest approach, collisions; the summary."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathlib import Path


@dataclass(slots=True)
class RobotReport:
    """What one robot did."""

    name: str
    distance: float
    closest: float
    collisions: int
    pose: tuple[float, float, float]


@dataclass(slots=True)
class SimReport:
    """What a run did, for the summary."""

    world: str
    sim_seconds: float
    wall_seconds: float
    mode: str
    robots: list[RobotReport]
    recorded: dict[str, int] = field(default_factory=dict)
    bag: Path | None = None
    picture: Path | None = None
    stalls: int = 0
    warnings: list[str] = field(default_factory=list)

    def lines(self) -> list[str]:
        """The summary printed at the end of a run."""
        factor = self.sim_seconds / self.wall_seconds if self.wall_seconds > 0 else math.inf
        out = [
            f"simulated {self.sim_seconds:.2f} s of {self.world} in {self.wall_seconds:.2f} s "
            f"({factor:.1f}x real time, {self.mode})"
        ]
        for robot in self.robots:
            closest = (
                "nothing within 5 m" if math.isinf(robot.closest) else (f"{robot.closest:.2f} m")
            )
            hits = (
                "no collisions"
                if robot.collisions == 0
                else (f"{robot.collisions} collision{'s' if robot.collisions != 1 else ''}")
            )
            x, y, yaw = robot.pose
            out.append(
                f"  {robot.name}: drove {robot.distance:.2f} m, closest approach to an obstacle "
                f"{closest}, {hits}; ends at x={x:.2f} y={y:.2f} yaw={yaw:.2f}"
            )
        out += [f"  cmd_vel {warning}" for warning in self.warnings]
        if self.stalls:
            out.append(f"  lock-step: went on without a silent controller {self.stalls} time(s)")
        if self.bag is not None:
            total = sum(self.recorded.values())
            out.append(f"  recorded {total} messages to {self.bag}/:")
            width = max((len(t) for t in self.recorded), default=0)
            out += [f"    {t:<{width}}  {n}" for t, n in sorted(self.recorded.items())]
        if self.picture is not None:
            out.append(f"  picture of the run: {self.picture}")
        return out
