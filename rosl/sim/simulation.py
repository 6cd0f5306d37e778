"""Stepping a world on an integer-nanosecond clock: physics, sensor schedules, statistics.

No bus here: :class:`Simulation` is driven by the sim node (or a test, or a benchmark) one
physics step at a time and says which publications fall due. Every rate fires on the first
step at or after its due time (30 Hz odometry on a 10 ms step comes out 30 or 40 ms apart, as
it would on any fixed-step simulator); a scan's index, not the number of scans computed,
seeds its noise, so skipping scans nobody listens to changes nothing that is published.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import pymunk

from rosl.sim import lidar as lidar_cast
from rosl.sim.robot import _FFI, _LIB, DiffDriveRobot
from rosl.sim.world import Geometry, WorldSpace
from rosl.sim.worldfile import Circle, Polygon

if TYPE_CHECKING:
    import numpy as np

    from rosl.sim.worldfile import Lidar, World

NS = 1_000_000_000
ROBOT_COLLISION = 1
CLEARANCE_REACH = 5.0  # metres: obstacles farther than this do not count as "close"


@dataclass(slots=True)
class Schedule:
    """A rate on the sim clock: due at round(k * 1e9 / rate) ns, k = 0, 1, 2, ..."""

    rate: float
    index: int = 0  # the next firing's k
    at_ns: float = field(init=False)  # when it is due (inf: never), kept by fire()

    def __post_init__(self) -> None:
        self.at_ns = self._at(self.index)

    def _at(self, index: int) -> float:
        return round(index * NS / self.rate) if self.rate > 0 else math.inf

    def due(self, now_ns: int) -> bool:
        """Whether the next firing is due at ``now_ns``."""
        return now_ns >= self.at_ns

    def fire(self, now_ns: int) -> int:
        """Take the due firing; return its k. Firings missed in one step are skipped."""
        index = self.index
        after = index + 1
        at_ns = round(after * NS / self.rate)  # due, so the rate is positive
        if now_ns >= at_ns:  # that one is due too: skip to the first after now
            after = max(after, math.floor(now_ns * self.rate / NS) + 1)
            at_ns = round(after * NS / self.rate)
        self.index, self.at_ns = after, at_ns
        return index


@dataclass(slots=True)
class SimRobot:
    """A robot with its publication schedules and what happened to it."""

    robot: DiffDriveRobot
    odom: Schedule
    joints: Schedule | None
    lidars: list[tuple[Lidar, Schedule]]
    path: list[tuple[int, float, float, float]] = field(default_factory=list)  # t, x, y, yaw
    distance: float = 0.0
    closest: float = math.inf
    collisions: int = 0
    last_scan: tuple[int, np.ndarray] | None = None

    @property
    def name(self) -> str:
        """The robot's name in the world."""
        return self.robot.spec.name


class Simulation:
    """A world in motion: call :meth:`step` and ask what is due."""

    def __init__(self, world: World, *, seed: int | None = None) -> None:
        self.world = world
        self.seed = world.seed if seed is None else seed
        self.space = WorldSpace(world)
        self.step_ns = world.step_ns
        self._dt = self.step_ns / NS
        self._space_step = self._first_space_step
        self.now_ns = 0
        self.steps = 0
        self.robots: list[SimRobot] = []
        for number, spec in enumerate(world.robots, start=1):
            robot = DiffDriveRobot(spec, self.space.space)
            robot.shape.collision_type = ROBOT_COLLISION
            robot.shape.filter = pymunk.ShapeFilter(group=number)
            model = spec.model
            self.robots.append(
                SimRobot(
                    robot,
                    Schedule(model.odom_rate),
                    Schedule(model.joint_states_rate) if model.joint_states_topic else None,
                    [(lidar, Schedule(lidar.rate)) for lidar in model.lidars],
                )
            )
        self.space.space.on_collision(
            ROBOT_COLLISION, None, begin=self._on_contact, separate=self._on_parting
        )
        self._by_shape = {r.robot.shape: r for r in self.robots}
        self._c_space = self.space.space._space
        self._query = _FFI.new("cpPointQueryInfo *")
        for sim_robot in self.robots:
            self._sample(sim_robot)

    # --- stepping ----------------------------------------------------------------------------

    def step(self) -> None:
        """Advance the physics by one fixed step."""
        dt = self._dt
        robots = self.robots
        for sim_robot in robots:
            sim_robot.robot.before_step(dt)
        self._space_step(dt)
        self.now_ns += self.step_ns
        self.steps += 1
        for sim_robot in robots:
            sim_robot.distance += sim_robot.robot.after_step(dt)

    def advance(self, stop: float, limit: float) -> None:
        """One step, then more while the clock is before ``stop`` and not after ``limit``.

        What calling :meth:`step` in that loop does, with the loop's calls and look-ups taken
        out of each step: the paced sim node runs the steps between two publications so.
        """
        dt, step_ns, robots = self._dt, self.step_ns, self.robots
        now = self.now_ns
        while True:
            for sim_robot in robots:
                sim_robot.robot.before_step(dt)
            self._space_step(dt)
            now += step_ns
            self.now_ns = now
            self.steps += 1
            for sim_robot in robots:
                sim_robot.distance += sim_robot.robot.after_step(dt)
            if now >= stop or now > limit:
                return

    def _first_space_step(self, dt: float) -> None:
        """Pymunk's own step (it checks the bodies added since), then chipmunk's directly."""
        space = self.space.space
        space.step(dt)
        if not space._bodies_to_check:  # nothing is added while stepping: skip the wrapper
            self._space_step = functools.partial(_LIB.cpSpaceStep, space._space)

    def _on_contact(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        del space, data
        counted = False
        for shape in arbiter.shapes:
            hit = self._by_shape.get(shape)
            if hit is not None:
                hit.robot.contacts += 1
                if not counted:  # one collision, even between two robots
                    hit.collisions += 1
                    counted = True

    def _on_parting(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: object) -> None:
        del space, data
        for shape in arbiter.shapes:
            hit = self._by_shape.get(shape)
            if hit is not None:
                hit.robot.contacts = max(0, hit.robot.contacts - 1)

    def sample(self) -> None:
        """Record each robot's pose for the path and its clearance (call at the odom rate)."""
        for sim_robot in self.robots:
            self._sample(sim_robot)

    def _sample(self, sim_robot: SimRobot) -> None:
        x, y, yaw = sim_robot.robot.pose
        sim_robot.path.append((self.now_ns, x, y, yaw))
        shape = sim_robot.robot.shape
        info = self._query
        if (
            _LIB.cpSpacePointQueryNearest(
                self._c_space, (x, y), CLEARANCE_REACH, shape.filter, info
            )
            == _FFI.NULL
        ):  # nothing within reach (pymunk's point_query_nearest, minus its objects)
            return
        distance = info.distance
        footprint = sim_robot.robot.spec.model.footprint
        if isinstance(footprint, Circle):
            sim_robot.closest = min(sim_robot.closest, distance - footprint.radius)
        elif distance - _circumscribed(footprint) < sim_robot.closest:  # could be closer
            sim_robot.closest = min(sim_robot.closest, self._clearance(shape, distance))

    def _clearance(self, robot: pymunk.Shape, reach: float) -> float:
        """The exact gap between a polygon footprint and the nearest obstacle (0 on contact).

        Between convex shapes the gap is reached at a corner of one of them: the footprint's
        corners are asked of the space, the obstacles' corners (centres, ends) of the footprint.
        """
        assert isinstance(robot, pymunk.Poly)
        space, body = self.space.space, robot.body
        assert body is not None  # a shape in a space has its body
        corners = [body.local_to_world(v) for v in robot.get_vertices()]
        best = math.inf
        for corner in corners:
            hit = space.point_query_nearest(corner, CLEARANCE_REACH, robot.filter)
            if hit is not None:
                best = min(best, hit.distance)
        box = robot.bb
        near = pymunk.BB(box.left - reach, box.bottom - reach, box.right + reach, box.top + reach)
        for other in space.bb_query(near, robot.filter):
            for point, radius in _features(other):
                best = min(best, robot.point_query(point).distance - radius)
        return max(0.0, best)

    # --- sensors -----------------------------------------------------------------------------

    def scan(self, sim_robot: SimRobot, lidar: Lidar, index: int) -> np.ndarray:
        """The ranges of scan number ``index`` of ``lidar`` on ``sim_robot``, now."""
        geometries = [self.space.geometry]
        others = [r for r in self.robots if r is not sim_robot]
        if self.space.bodies or others:
            moving = self.space.dynamic_geometry()
            robots = _robot_geometry(others)
            geometries += [moving, robots]
        ranges = lidar_cast.scan(
            lidar, sim_robot.robot.pose, geometries, seed=self.seed, index=index
        )
        sim_robot.last_scan = (self.now_ns, ranges)
        return ranges


def _circumscribed(footprint: Polygon) -> float:
    """The distance from the robot's centre to its footprint's farthest corner."""
    return max(math.hypot(x, y) for x, y in footprint.points)


def _features(shape: pymunk.Shape) -> list[tuple[tuple[float, float], float]]:
    """An obstacle's corners (or centre, or ends) in the world, with its rounding radius."""
    body = shape.body
    assert body is not None  # a shape in a space has its body
    if isinstance(shape, pymunk.Circle):
        return [(body.local_to_world(shape.offset), shape.radius)]
    if isinstance(shape, pymunk.Segment):
        return [
            (body.local_to_world(shape.a), shape.radius),
            (body.local_to_world(shape.b), shape.radius),
        ]
    assert isinstance(shape, pymunk.Poly)
    return [(body.local_to_world(v), shape.radius) for v in shape.get_vertices()]


def _robot_geometry(robots: list[SimRobot]) -> Geometry:
    shapes: list[Circle | Polygon] = []
    for sim_robot in robots:
        x, y, yaw = sim_robot.robot.pose
        foot = sim_robot.robot.spec.model.footprint
        if isinstance(foot, Circle):
            shapes.append(Circle(sim_robot.name, (x, y), foot.radius))
        else:
            c, s = math.cos(yaw), math.sin(yaw)
            shapes.append(
                Polygon(
                    sim_robot.name,
                    tuple((x + c * px - s * py, y + s * px + c * py) for px, py in foot.points),
                )
            )
    return Geometry(tuple(shapes))
