"""The diff drive on sim time, no bus: the seed's square, exact arcs, limits, bad commands, odom."""

from __future__ import annotations

import cmath
import math
from typing import TYPE_CHECKING

import pytest

from rosl.sim.simulation import Simulation
from rosl.sim.worldfile import load_world, resolve_world
from tests.sim.conftest import NS, run_until

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

TICK_NS = 100_000_000  # the velocity controller's 100 ms timer


def empty_sim() -> Simulation:
    return Simulation(load_world(resolve_world("empty")))


def square_commands(ticks: int) -> list[tuple[float, float]]:
    """What examples/tutorial_pkg's velocity_controller publishes on its first ``ticks`` ticks."""
    phase, step, out = 0, 0, []
    for _ in range(ticks):
        step += 1
        if phase == 0:
            out.append((0.2, 0.0))
            if step >= 20:
                phase, step = 1, 0
        else:
            out.append((0.0, 0.5))
            if step >= 16:
                phase, step = 0, 0
    return out


def drive_square(sim: Simulation, legs: int) -> None:
    """Apply the controller's commands at t = 0.1, 0.2, ... s (its timer on sim time), then stop."""
    robot = sim.robots[0].robot
    commands = square_commands(36 * legs)
    for k, command in enumerate(commands, start=1):
        run_until(sim, k * TICK_NS)
        assert robot.command(*command) is None
    run_until(sim, (len(commands) + 1) * TICK_NS)
    robot.command(0.0, 0.0)
    run_until(sim, (len(commands) + 6) * TICK_NS)


def test_the_velocity_controllers_pattern_turns_0_8_rad_per_corner_and_closes_after_8_legs() -> (
    None
):
    # 0.2 m/s for 20 x 100 ms is a 0.4 m leg; 0.5 rad/s for 16 x 100 ms is 0.8 rad (not pi/2),
    # so the "square" closes after 8 legs (6.4 rad), at 0.4 * sum(e^(i 0.8 j)), j = 0..7
    sim = empty_sim()
    drive_square(sim, legs=4)
    x, y, yaw = sim.robots[0].robot.pose
    half = 0.4 * sum(cmath.exp(0.8j * j) for j in range(4))
    assert yaw == pytest.approx(3.2, abs=1e-9)
    assert abs(complex(x, y) - half) < 0.01, (x, y, half)
    assert abs(complex(x, y)) > 0.9  # after 4 legs it is across the figure, not home

    sim = empty_sim()
    drive_square(sim, legs=8)
    x, y, yaw = sim.robots[0].robot.pose
    closed = 0.4 * sum(cmath.exp(0.8j * j) for j in range(8))
    assert yaw == pytest.approx(6.4, abs=1e-9)
    assert abs(complex(x, y) - closed) < 0.01, (x, y, closed)
    assert math.hypot(x, y) < 0.15
    assert sim.robots[0].distance == pytest.approx(8 * 0.4, abs=0.01)
    assert sim.robots[0].collisions == 0


def test_a_commanded_arc_after_the_ramp_matches_the_exact_arc_within_millimetres() -> None:
    sim = empty_sim()
    robot = sim.robots[0].robot
    v, w = 0.2, 0.5
    assert robot.command(v, w) is None
    run_until(sim, NS // 2)  # linear ramp: 0.2 s at 1 m/s^2; angular: 0.04 s
    assert robot.odometry()[1] == pytest.approx((v, w), abs=1e-12)
    x0, y0, yaw0 = robot.pose
    for seconds in (1, 3, 6, 12):  # 12 s is almost a full circle (6 rad)
        run_until(sim, NS // 2 + seconds * NS)
        radius, turned = v / w, w * seconds
        ex = x0 + radius * (math.sin(yaw0 + turned) - math.sin(yaw0))
        ey = y0 - radius * (math.cos(yaw0 + turned) - math.cos(yaw0))
        x, y, yaw = robot.pose
        assert math.hypot(x - ex, y - ey) < 3e-3, (seconds, x - ex, y - ey)
        assert yaw == pytest.approx(yaw0 + turned, abs=1e-9)


@pytest.mark.parametrize(
    ("command", "clamped"),
    [
        ((0.3, 0.0), (0.22, 0.0)),
        ((0.0, 5.0), (0.0, 2.84)),
        ((-1.0, -4.0), (-0.22, -2.84)),
        ((500.0, 0.0), (0.22, 0.0)),
    ],
)
def test_commands_beyond_the_burgers_limits_are_clamped_with_a_warning(
    command: tuple[float, float], clamped: tuple[float, float]
) -> None:
    sim = empty_sim()
    robot = sim.robots[0].robot
    warning = robot.command(*command)
    assert warning is not None
    assert "clamped" in warning
    assert "turtlebot3_burger" in warning
    assert f"({clamped[0]:g}, {clamped[1]:g})" in warning
    run_until(sim, 3 * NS)  # past every ramp
    assert robot.odometry()[1] == pytest.approx(clamped, abs=1e-9)
    assert robot.command(*clamped) is None  # the limits themselves are fine


@pytest.mark.parametrize(
    ("command", "words"),
    [
        ((math.nan, 0.0), "non-finite"),
        ((0.0, math.nan), "non-finite"),
        ((math.inf, 0.0), "non-finite"),
        ((0.1, -math.inf), "non-finite"),
        ((1e9, 0.0), "absurd"),
        ((0.0, -1e12), "absurd"),
    ],
)
def test_nan_inf_and_absurd_commands_are_ignored_with_a_warning_and_the_sim_keeps_going(
    command: tuple[float, float], words: str
) -> None:
    sim = empty_sim()
    robot = sim.robots[0].robot
    assert robot.command(0.1, 0.2) is None
    run_until(sim, NS)
    warning = robot.command(*command)
    assert warning is not None
    assert "ignored" in warning
    assert words in warning
    run_until(sim, 3 * NS)
    x, y, yaw = robot.pose
    assert all(math.isfinite(value) for value in (x, y, yaw, sim.robots[0].distance))
    assert robot.odometry()[1] == pytest.approx((0.1, 0.2), abs=1e-9)  # the last good command
    assert sim.now_ns == 3 * NS


def test_odometry_is_relative_to_the_spawn_pose(write_world: Callable[..., Path]) -> None:
    spawn = (1.0, -2.0, 1.0)
    world = write_world(f"""
        format: rosl-world/1
        robots:
          - {{name: burger, model: turtlebot3_burger, pose: [{spawn[0]}, {spawn[1]}, {spawn[2]}]}}
    """)
    sim = Simulation(load_world(world))
    robot = sim.robots[0].robot
    assert robot.pose == spawn
    assert robot.odometry()[0] == (0.0, 0.0, 0.0)

    robot.command(0.2, 0.0)
    run_until(sim, 3 * NS)
    robot.command(0.1, -0.4)
    run_until(sim, 7 * NS)

    (ox, oy, oyaw), _ = robot.odometry()
    x, y, yaw = robot.pose
    c, s = math.cos(spawn[2]), math.sin(spawn[2])
    assert spawn[0] + c * ox - s * oy == pytest.approx(x, abs=1e-12)
    assert spawn[1] + s * ox + c * oy == pytest.approx(y, abs=1e-12)
    assert spawn[2] + oyaw == pytest.approx(yaw, abs=1e-12)
    # the straight part went along the odom frame's x axis
    sim = Simulation(load_world(world))
    sim.robots[0].robot.command(0.2, 0.0)
    run_until(sim, 3 * NS)
    (ox, oy, oyaw), _ = sim.robots[0].robot.odometry()
    assert ox == pytest.approx(0.2 * 3 - 0.02, abs=2e-3)  # minus the 0.2 s ramp at 1 m/s^2
    assert oy == pytest.approx(0.0, abs=1e-9)  # the wheels' grip is solved in floating point
    assert oyaw == 0.0


@pytest.mark.parametrize("world_name", ["turtlebot3_world", "dolly_field"])
def test_advance_leaves_the_world_as_the_same_steps_one_by_one(world_name: str) -> None:
    # the paced sim node's steps between publications: one step, then more while before the
    # stop and not after the limit; bodies, clock, counts and distances as step() leaves them
    one_by_one, advanced = (Simulation(load_world(resolve_world(world_name))) for _ in range(2))
    for sim in (one_by_one, advanced):
        sim.robots[0].robot.command(0.2, 0.9)
    for stop, limit in [(35_000_000, math.inf), (10**9, 4.2e8), (0, math.inf), (10**12, 1.5e9)]:
        one_by_one.step()
        while one_by_one.now_ns < stop and one_by_one.now_ns <= limit:
            one_by_one.step()
        advanced.advance(stop, limit)
        assert advanced.now_ns == one_by_one.now_ns
        assert advanced.steps == one_by_one.steps
        for a, b in zip(advanced.robots, one_by_one.robots, strict=True):
            assert a.robot.pose == b.robot.pose
            assert a.robot.wheels == b.robot.wheels
            assert a.distance == b.distance
    assert advanced.now_ns == 1_510_000_000  # the last limit, passed by one step
