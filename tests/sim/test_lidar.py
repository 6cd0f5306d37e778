"""Scan geometry against pymunk's own segment queries, Gazebo's conventions, seeded noise."""

from __future__ import annotations

import dataclasses
import math
from typing import TYPE_CHECKING

import numpy as np
import pymunk
import pytest

from rosl.sim import lidar as lidar_cast
from rosl.sim import messages as build
from rosl.sim.errors import WorldFileError
from rosl.sim.simulation import Simulation
from rosl.sim.world import WorldSpace
from rosl.sim.worldfile import load_world, resolve_world
from tests.sim.conftest import NS, run_until

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from rosl.sim.worldfile import Lidar

ANY = pymunk.ShapeFilter()


def pymunk_ranges(
    space: pymunk.Space,
    x: float,
    y: float,
    first: float,
    inc: float,
    n: int,
    reach: float,
    shape_filter: pymunk.ShapeFilter = ANY,
) -> np.ndarray:
    """The reference: one zero-radius ``segment_query_first`` per ray."""
    out = np.full(n, np.inf)
    for k in range(n):
        angle = first + inc * k
        end = (x + reach * math.cos(angle), y + reach * math.sin(angle))
        hit = space.segment_query_first((x, y), end, 0.0, shape_filter)
        if hit is not None:
            out[k] = hit.alpha * reach
    return out


def free_poses(space: pymunk.Space, half: float, count: int, seed: int) -> list[tuple[float, ...]]:
    """Random (x, y, yaw) at least 0.2 m from anything, in [-half, half]^2."""
    rng = np.random.default_rng(seed)
    poses: list[tuple[float, ...]] = []
    while len(poses) < count:
        x, y = rng.uniform(-half, half, 2)
        if space.point_query_nearest((x, y), 0.2, ANY) is None:
            poses.append((float(x), float(y), float(rng.uniform(-math.pi, math.pi))))
    return poses


def assert_same_ranges(got: np.ndarray, want: np.ndarray, tolerance: float) -> None:
    assert np.array_equal(np.isposinf(got), np.isposinf(want)), np.flatnonzero(
        np.isposinf(got) != np.isposinf(want)
    )
    finite = np.isfinite(want)
    assert np.all(np.isfinite(got[finite]))
    if finite.any():
        worst = float(np.max(np.abs(got[finite] - want[finite])))
        assert worst <= tolerance, worst


@pytest.mark.parametrize(("name", "half"), [("turtlebot3_world", 4.0), ("dolly_field", 16.0)])
def test_ranges_match_pymunks_segment_queries_at_random_free_poses(name: str, half: float) -> None:
    world = load_world(resolve_world(name))
    space = WorldSpace(world)
    lidar = world.robots[0].model.lidars[0]
    inc = lidar_cast.increment(lidar)
    geometries = [space.geometry, space.dynamic_geometry()]
    hits = misses = 0
    for x, y, yaw in free_poses(space.space, half, 150, seed=7):
        first = yaw + lidar.angle_min
        got = lidar_cast.cast(x, y, first, inc, lidar.samples, lidar.range_max, geometries)
        want = pymunk_ranges(space.space, x, y, first, inc, lidar.samples, lidar.range_max)
        assert_same_ranges(got, want, 1e-9)
        hits += int(np.isfinite(want).sum())
        misses += int(np.isinf(want).sum())
    assert hits > 5000  # the comparison saw plenty of both
    assert misses > 1000


def test_a_one_ray_lidar_matches_pymunks_segment_query() -> None:
    world = load_world(resolve_world("turtlebot3_world"))
    space = WorldSpace(world)
    hits = 0
    for x, y, yaw in free_poses(space.space, 4.0, 300, seed=11):
        got = lidar_cast.cast(x, y, yaw, 0.0, 1, 3.5, [space.geometry])
        want = pymunk_ranges(space.space, x, y, yaw, 0.0, 1, 3.5)
        assert_same_ranges(got, want, 1e-9)
        hits += int(np.isfinite(want).sum())
    assert 100 < hits < 300  # both hits and misses were compared


def test_the_full_scan_pipeline_sees_other_robots_and_moved_dynamic_bodies(
    write_world: Callable[..., Path],
) -> None:
    world = write_world("""
        format: rosl-world/1
        static:
          - {type: polygon, name: fence, ring: true, thickness: 0.3,
             points: [[8, 8], [-8, 8], [-8, -8], [8, -8]]}
        dynamic:
          - {type: cylinder, name: target, center: [5.0, -3.0], radius: 1.0, kinematic: true}
          - {type: box, name: crate, center: [-3.0, 0.0], size: [1.0, 0.6], mass: 2.0}
        robots:
          - {name: dolly, model: dolly, pose: [0.0, 0.0, 0.0], namespace: dolly}
          - {name: burger, model: turtlebot3_burger, pose: [2.5, 0.3, 0.5]}
          - {name: other, model: dolly, pose: [0.0, 3.0, 1.0], namespace: other}
    """)
    sim = Simulation(load_world(world))
    target = sim.space.bodies[0][0]
    checked = 0
    for step, (tx, ty) in enumerate([(5.0, -3.0), (3.0, -1.0), (-2.0, -4.0), (1.0, 5.0)]):
        target.position = (tx, ty)
        for k, sim_robot in enumerate(sim.robots):
            sim_robot.robot.command(0.3, 0.4 * (k - 1))
        run_until(sim, (step + 1) * NS)
        for sim_robot in sim.robots:
            lidar = dataclasses.replace(sim_robot.robot.spec.model.lidars[0], noise_stddev=0.0)
            got = sim.scan(sim_robot, lidar, index=step)
            x, y, yaw = sim_robot.robot.pose
            c, s = math.cos(yaw), math.sin(yaw)
            sx, sy = x + c * lidar.xy[0] - s * lidar.xy[1], y + s * lidar.xy[0] + c * lidar.xy[1]
            want = pymunk_ranges(
                sim.space.space, sx, sy, yaw + lidar.angle_min, lidar_cast.increment(lidar),
                lidar.samples, lidar.range_max, sim_robot.robot.shape.filter,
            )  # fmt: skip
            want[want < lidar.range_min] = -np.inf
            assert np.array_equal(np.isneginf(got), np.isneginf(want))
            assert_same_ranges(got, want.astype(np.float32), 1e-5)
            checked += int(np.isfinite(want).sum())
    assert checked > 300


def test_a_robot_sees_another_robot_in_front_of_it(write_world: Callable[..., Path]) -> None:
    world = write_world("""
        format: rosl-world/1
        robots:
          - {name: a, model: turtlebot3_burger, pose: [0.0, 0.0, 0.0]}
          - {name: b, model: turtlebot3_burger, pose: [1.0, 0.0, 0.0], namespace: b}
    """)
    sim = Simulation(load_world(world))
    a, b = sim.robots
    lidar = dataclasses.replace(a.robot.spec.model.lidars[0], noise_stddev=0.0)
    ranges = sim.scan(a, lidar, index=0)
    # ray 0 looks straight ahead from base_scan (x = -0.032) to b's circle (r = 0.105)
    assert ranges[0] == pytest.approx(1.0 - 0.105 + 0.032, abs=1e-6)
    assert np.isposinf(ranges[180])  # nothing behind it
    assert np.isposinf(sim.scan(b, lidar, index=0)[0])  # b looks away from a


def test_ranges_follow_gazebos_laser_scan_conventions() -> None:
    world = load_world(resolve_world("turtlebot3_world"))
    lidar = world.robots[0].model.lidars[0]
    angles = lidar_cast.angles(lidar)
    assert lidar_cast.increment(lidar) == (6.28 - 0.0) / (360 - 1)
    assert len(angles) == 360
    assert angles[0] == 0.0
    assert angles[-1] == pytest.approx(6.28, abs=1e-12)

    message = build.laser_scan(lidar, np.zeros(360, dtype=np.float32), 1_500_000_000)
    assert message.header.frame_id == "base_scan"
    assert (message.header.stamp.sec, message.header.stamp.nanosec) == (1, 500_000_000)
    assert message.angle_min == 0.0
    assert message.angle_max == pytest.approx(6.28)
    assert message.angle_increment == pytest.approx(6.28 / 359)
    assert (message.range_min, message.range_max) == (pytest.approx(0.12), pytest.approx(3.5))
    assert message.scan_time == pytest.approx(0.2)
    assert len(message.ranges) == 360

    empty = load_world(resolve_world("empty"))
    space = WorldSpace(empty)
    ranges = lidar_cast.scan(lidar, (0.0, 0.0, 0.0), [space.geometry], seed=0, index=0)
    assert ranges.dtype == np.float32
    assert np.all(np.isposinf(ranges))  # no return: +inf (REP 117), never range_max or NaN


def test_returns_closer_than_range_min_are_minus_inf_and_beyond_range_max_plus_inf(
    write_world: Callable[..., Path],
) -> None:
    world = load_world(
        write_world("""
            format: rosl-world/1
            static:
              - {type: box, name: near, center: [0.6, 0.0], size: [0.2, 0.4]}
              - {type: box, name: far, center: [-3.5, 0.0], size: [0.2, 8.0]}
        """)
    )
    lidar = load_world(resolve_world("empty")).robots[0].model.lidars[0]
    lidar = dataclasses.replace(lidar, noise_stddev=0.0)
    geometry = [WorldSpace(world).geometry]
    # base_scan is 0.032 m behind the robot's centre; the near face is at x = 0.5
    ranges = lidar_cast.scan(lidar, (0.42, 0.0, 0.0), geometry, seed=0, index=0)
    assert np.isneginf(ranges[0])  # 0.112 m < range_min 0.12
    assert not np.isnan(ranges).any()
    assert ranges[0 + 90] == np.inf  # straight left: nothing
    # the far face is at x = -3.4
    behind = lidar_cast.scan(lidar, (0.0, 0.0, math.pi), geometry, seed=0, index=0)
    assert behind[0] == pytest.approx(3.4 + 0.032, abs=1e-6)
    beyond = lidar_cast.scan(lidar, (0.2, 0.0, math.pi), geometry, seed=0, index=0)
    assert np.isposinf(beyond[0])  # 3.632 m > range_max 3.5


def noisy_scan(lidar: Lidar, seed: int, index: int) -> np.ndarray:
    space = WorldSpace(load_world(resolve_world("turtlebot3_world")))
    return lidar_cast.scan(lidar, (-2.0, -0.5, 0.3), [space.geometry], seed=seed, index=index)


def test_noise_is_seeded_by_the_seed_and_the_scans_index() -> None:
    lidar = load_world(resolve_world("turtlebot3_world")).robots[0].model.lidars[0]
    assert lidar.noise_stddev == pytest.approx(0.01)
    first = noisy_scan(lidar, seed=0, index=3)
    assert np.array_equal(first, noisy_scan(lidar, seed=0, index=3), equal_nan=True)
    assert not np.array_equal(first, noisy_scan(lidar, seed=0, index=4))
    assert not np.array_equal(first, noisy_scan(lidar, seed=1, index=3))

    exact = noisy_scan(dataclasses.replace(lidar, noise_stddev=0.0), seed=0, index=3)
    finite = np.isfinite(exact) & np.isfinite(first)
    assert finite.sum() > 300  # the arena is small: almost every ray hits something
    error = (first[finite] - exact[finite]).astype(np.float64)
    assert abs(error.mean()) < 0.003
    assert 0.008 < error.std() < 0.012
    assert np.array_equal(np.isposinf(first), np.isposinf(exact))


def test_a_simulations_seed_option_changes_the_noise_and_nothing_else() -> None:
    world = load_world(resolve_world("turtlebot3_world"))
    scans = {}
    for seed in (None, 0, 42):
        sim = Simulation(world, seed=seed)
        sim.robots[0].robot.command(0.1, 0.2)
        run_until(sim, 2 * NS)
        scans[seed] = (
            sim.robots[0].robot.pose,
            sim.scan(sim.robots[0], sim.robots[0].lidars[0][0], 9),
        )
    assert scans[None][0] == scans[0][0] == scans[42][0]
    assert np.array_equal(scans[None][1], scans[0][1])  # the world's seed is 0
    assert not np.array_equal(scans[0][1], scans[42][1])


def test_the_scan_sees_a_segment_wall_where_the_robot_collides_with_it(
    write_world: Callable[..., Path],
) -> None:
    # a segment wall has a radius (default 1 cm): pymunk collides with its surface
    world = load_world(
        write_world("""
            format: rosl-world/1
            static:
              - {type: segment, name: thick, points: [[2.0, -2.0], [2.0, 2.0]], radius: 0.1}
        """)
    )
    space = WorldSpace(world)
    got = lidar_cast.cast(0.0, 0.0, -0.5, 0.01, 101, 3.5, [space.geometry])
    want = pymunk_ranges(space.space, 0.0, 0.0, -0.5, 0.01, 101, 3.5)
    assert want[50] == pytest.approx(1.9)
    assert_same_ranges(got, want, 1e-9)


def test_a_non_convex_polygon_is_refused_or_seen_where_the_robot_collides_with_it(
    write_world: Callable[..., Path],
) -> None:
    path = write_world("""
        format: rosl-world/1
        static:
          - {type: polygon, name: ell,
             points: [[1.0, -1.0], [2.0, -1.0], [2.0, 1.0], [1.5, 1.0], [1.5, 0.0], [1.0, 0.0]]}
    """)
    try:
        world = load_world(path)
    except WorldFileError as err:  # refusing it (naming the line) is fine too
        refused = str(err)
        assert f"{path}:3:" in refused
        return
    space = WorldSpace(world)
    got = lidar_cast.cast(0.0, 0.5, -0.3, 0.01, 61, 3.5, [space.geometry])
    want = pymunk_ranges(space.space, 0.0, 0.5, -0.3, 0.01, 61, 3.5)
    assert_same_ranges(got, want, 1e-9)
