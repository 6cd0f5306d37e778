"""Collisions: robots driven at full speed into walls and pillars stop at the surface, for good."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import pytest

from rosl.sim.simulation import Simulation
from rosl.sim.worldfile import load_world

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

BURGER_RADIUS = 0.105
ARENA = """
    format: rosl-world/1
    static:
      - {type: box, name: wall, center: [1.0, 0.0], size: [0.2, 4.0]}
      - {type: segment, name: thin, points: [[-1.0, -2.0], [-1.0, 2.0]]}
      - {type: cylinder, name: pillar, center: [0.0, 1.0], radius: 0.15}
    robots:
      - {name: burger, model: turtlebot3_burger, pose: [0.0, 0.0, %s]}
"""
FAST_ROBOT = """
    format: rosl-robot/1
    name: fast
    footprint: {type: circle, radius: 0.105}
    drive: {wheel_separation: 0.16, wheel_radius: 0.033, max_linear: 20.0, max_linear_accel: 100.0}
"""


def push(sim: Simulation, linear: float, seconds: float) -> list[tuple[float, float, float]]:
    """Command ``linear`` and step for ``seconds``; the poses after each step."""
    robot = sim.robots[0].robot
    robot.command(linear, 0.0)
    poses = []
    for step in range(round(seconds * 1e9 / sim.step_ns)):
        sim.step()
        if step % 3 == 0:
            sim.sample()  # what the sim node does at the odom rate
        poses.append(robot.pose)
    return poses


def box_gap(pose: tuple[float, float, float]) -> float:
    return 0.9 - (pose[0] + BURGER_RADIUS)


def segment_gap(pose: tuple[float, float, float]) -> float:
    return (pose[0] - BURGER_RADIUS) - (-1.0 + 0.01)  # the segment's default 1 cm radius


def pillar_gap(pose: tuple[float, float, float]) -> float:
    return math.hypot(pose[0], pose[1] - 1.0) - 0.15 - BURGER_RADIUS


OBSTACLES = pytest.mark.parametrize(
    ("yaw", "gap", "stop"),
    [
        (0.0, box_gap, (0.9 - BURGER_RADIUS, 0.0)),
        (math.pi, segment_gap, (-1.0 + 0.01 + BURGER_RADIUS, 0.0)),
        (math.pi / 2, pillar_gap, (0.0, 1.0 - 0.15 - BURGER_RADIUS)),
    ],
    ids=["box", "segment", "pillar"],
)


@OBSTACLES
def test_the_burger_at_full_speed_never_gets_into_an_obstacle(
    write_world: Callable[..., Path],
    yaw: float,
    gap: Callable[[tuple[float, float, float]], float],
    stop: tuple[float, float],
) -> None:
    sim = Simulation(load_world(write_world(ARENA % yaw)))
    poses = push(sim, 0.22, 60.0)  # 13 m worth of driving into an obstacle 0.8 m away
    assert min(gap(pose) for pose in poses) > -0.005, "went into the obstacle"
    robot = sim.robots[0]
    assert robot.collisions >= 1
    assert robot.closest == pytest.approx(0.0, abs=0.005)
    assert robot.distance > math.hypot(*stop) - 0.01


@OBSTACLES
def test_the_burger_pushing_into_an_obstacle_stays_where_it_hit_it(
    write_world: Callable[..., Path],
    yaw: float,
    gap: Callable[[tuple[float, float, float]], float],
    stop: tuple[float, float],
) -> None:
    # a diff drive cannot move sideways: pushing on, it stalls at the surface (Gazebo, Stage)
    sim = Simulation(load_world(write_world(ARENA % yaw)))
    poses = push(sim, 0.22, 60.0)
    sideways = max(abs(-math.sin(yaw) * p[0] + math.cos(yaw) * p[1]) for p in poses)
    assert sideways < 0.005, f"slid {sideways:.3f} m sideways with its heading fixed"
    x, y, _ = poses[-1]
    assert abs(gap(poses[-1])) < 0.005
    assert math.hypot(x - stop[0], y - stop[1]) < 0.005, f"ended at ({x:.3f}, {y:.3f})"


def test_dolly_at_its_top_speed_stops_at_a_wall(write_world: Callable[..., Path]) -> None:
    world = write_world("""
        format: rosl-world/1
        static:
          - {type: box, name: wall, center: [3.0, 0.0], size: [0.1, 6.0]}
        robots:
          - {name: dolly, model: dolly, pose: [0.0, 0.0, 0.0], namespace: dolly}
    """)
    sim = Simulation(load_world(world))
    poses = push(sim, 1.0, 30.0)
    stop = 3.0 - 0.05 - 0.5  # the wall's face minus half of Dolly's 1 m length
    assert max(p[0] for p in poses) < stop + 0.01
    assert poses[-1][0] == pytest.approx(stop, abs=0.01)
    assert sim.robots[0].collisions >= 1


def test_the_closest_approach_of_a_box_robot_touching_a_wall_is_zero(
    write_world: Callable[..., Path],
) -> None:
    world = write_world("""
        format: rosl-world/1
        static:
          - {type: box, name: wall, center: [3.0, 0.0], size: [0.1, 6.0]}
        robots:
          - {name: dolly, model: dolly, pose: [0.0, 0.0, 0.0], namespace: dolly}
    """)
    sim = Simulation(load_world(world))
    push(sim, 1.0, 10.0)
    assert sim.robots[0].collisions >= 1
    # its nose touches the wall; the summary must not say "closest approach 0.25 m"
    assert sim.robots[0].closest < 0.01, sim.robots[0].closest


def test_a_fast_robot_does_not_tunnel_through_a_thin_wall(write_world: Callable[..., Path]) -> None:
    world = write_world(
        """
        format: rosl-world/1
        static:
          - {type: segment, name: thin, points: [[2.0, -2.0], [2.0, 2.0]], radius: 0.005}
        robots:
          - {name: fast, model: fast, pose: [0.0, 0.0, 0.0]}
        """,
        robots={"fast": FAST_ROBOT},
    )
    for speed in (2.0, 5.0, 10.0, 20.0):  # up to 20 cm a step against a 1 cm wall
        sim = Simulation(load_world(world))
        poses = push(sim, speed, 10.0)
        assert max(p[0] for p in poses) < 2.0, f"tunnelled at {speed} m/s"
        assert sim.robots[0].collisions >= 1


def test_a_robot_touching_a_wall_can_back_away_and_turn(write_world: Callable[..., Path]) -> None:
    sim = Simulation(load_world(write_world(ARENA % 0.0)))
    push(sim, 0.22, 10.0)
    x_at_wall = sim.robots[0].robot.pose[0]
    poses = push(sim, -0.2, 2.0)
    assert poses[-1][0] < x_at_wall - 0.3  # not glued to the wall
    robot = sim.robots[0].robot
    robot.command(0.0, 1.0)
    for _ in range(100):
        sim.step()
    assert robot.pose[2] == pytest.approx(1.0 - 0.04, abs=0.01)  # 0.08 s ramp to 1 rad/s
