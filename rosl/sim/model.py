"""What a world is made of: obstacle shapes, robot models (drive, frames, LiDARs), worlds.

Plain frozen records; :mod:`rosl.sim.worldfile` reads them from YAML, the rest of the
simulator only reads them. Metres, radians, poses ``(x, y, yaw)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from pathlib import Path

Point = tuple[float, float]


def signed_area(points: list[Point] | tuple[Point, ...]) -> float:
    """Twice a polygon's signed area (positive when its points run counter-clockwise)."""
    ring = list(points)
    return sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(ring, ring[1:] + ring[:1], strict=True))


@dataclass(frozen=True, slots=True)
class Circle:
    """A circle obstacle (static or a dynamic body's shape)."""

    name: str
    center: Point
    radius: float


@dataclass(frozen=True, slots=True)
class Polygon:
    """A convex polygon obstacle (counter-clockwise points)."""

    name: str
    points: tuple[Point, ...]


@dataclass(frozen=True, slots=True)
class Segment:
    """A thin wall: a segment with a radius."""

    name: str
    a: Point
    b: Point
    radius: float = 0.01


Shape = Circle | Polygon | Segment


@dataclass(frozen=True, slots=True)
class DynamicBody:
    """A movable body: its shape, mass, and whether it is kinematic (moved by code)."""

    shape: Shape
    mass: float
    kinematic: bool


@dataclass(frozen=True, slots=True)
class Lidar:
    """A 2D laser scanner (Gazebo's ray sensor conventions)."""

    name: str
    frame_id: str
    topic: str
    rate: float
    samples: int
    angle_min: float
    angle_max: float
    range_min: float
    range_max: float
    noise_stddev: float = 0.0
    xy: Point = (0.0, 0.0)  # mount position in the robot frame (from frames when absent)


@dataclass(frozen=True, slots=True)
class Frame:
    """A fixed frame of the robot (published once on /tf_static)."""

    name: str
    parent: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    joint: str | None = None  # a wheel: turns about its z axis with this joint (on /tf)


@dataclass(frozen=True, slots=True)
class RobotModel:
    """A robot model: footprint, drive, frames and sensors."""

    name: str
    footprint: Circle | Polygon
    mass: float
    wheel_separation: float
    wheel_radius: float
    max_linear: float
    max_angular: float
    max_linear_accel: float
    cmd_vel: str
    odom_topic: str
    odom_frame: str
    base_frame: str
    odom_rate: float
    joint_states_topic: str | None
    joint_states_rate: float
    joints: tuple[str, ...]
    frames: tuple[Frame, ...]
    lidars: tuple[Lidar, ...]
    path: Path | None = None


@dataclass(frozen=True, slots=True)
class RobotSpec:
    """A robot placed in a world."""

    name: str
    model: RobotModel
    pose: tuple[float, float, float]
    namespace: str


@dataclass(frozen=True, slots=True)
class World:
    """A parsed world file."""

    name: str
    path: Path | None
    step_ns: int
    iterations: int
    seed: int
    statics: tuple[Shape, ...]
    dynamics: tuple[DynamicBody, ...]
    robots: tuple[RobotSpec, ...]
    extra: dict[str, Any] = field(default_factory=dict)
