"""The sim's hand-packed CDR is byte for byte what rosbags writes for the same message."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import pytest

from rosl.idl import registry
from rosl.sim import encode
from rosl.sim import messages as build
from rosl.sim.simulation import Simulation
from rosl.sim.worldfile import load_world, resolve_world

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.sim.simulation import SimRobot

NS = 1_000_000_000


@pytest.mark.parametrize("world_name", ["turtlebot3_world", "dolly_field", "empty"])
def test_every_high_rate_message_packs_to_the_same_bytes_as_the_message_object(world_name):
    store = registry.store()
    sim = Simulation(load_world(resolve_world(world_name)))
    robot = sim.robots[0]
    rng = np.random.default_rng(7)
    compared = 0
    for k in range(8):
        robot.robot.command(float(rng.uniform(-0.2, 0.2)), float(rng.uniform(-1.0, 1.0)))
        for _ in range(int(rng.integers(5, 60))):
            sim.step()
        now = sim.now_ns + int(rng.integers(0, 10**9)) + k * 10**9
        pairs = [
            (build.clock(now), build.clock_bytes(now)),
            (build.odometry(robot, now), build.odometry_bytes(robot, now)),
            (build.odom_tf(robot, now), build.tf_bytes([build.odom_transform(robot)], now)),
        ]
        if robot.robot.spec.model.joints:
            pairs.append(
                (build.wheel_tf(robot, now), build.tf_bytes(build.wheel_transforms(robot), now))
            )
            pairs.append((build.joint_states(robot, now), build.joint_states_bytes(robot, now)))
        for lidar in robot.robot.spec.model.lidars:
            ranges = sim.scan(robot, lidar, k)
            pairs.append(
                (build.laser_scan(lidar, ranges, now), build.laser_scan_bytes(lidar, ranges, now))
            )
            packed = build.RobotEncoder(robot).scan_packer(lidar)(*divmod(now, NS), ranges)
            pairs.append((build.laser_scan(lidar, ranges, now), packed))
        for message, packed in pairs:
            assert store.serialize(message) == packed, message.__msgtype__
            compared += 1
    assert compared >= 8 * 4


def test_strings_of_every_length_keep_cdr_alignment():
    # frame names of length 0..9 move the doubles across every alignment case
    store = registry.store()
    registry.get_message_class("tf2_msgs/msg/TFMessage")
    for length in range(10):
        parent, child = b"p" * length, b"c" * (9 - length)
        values = (1.0, -2.0, 0.5, 0.0, 0.0, math.sin(0.3), math.cos(0.3))
        packed = encode.tf_message(123_456_789_012, [(parent, child, values)])
        decoded = store.deserialize(packed, "tf2_msgs/msg/TFMessage")
        transform = decoded.transforms[0]
        assert transform.header.frame_id == parent.decode()
        assert transform.child_frame_id == child.decode()
        assert transform.header.stamp.sec == 123
        assert transform.header.stamp.nanosec == 456_789_012
        assert transform.transform.rotation.w == pytest.approx(math.cos(0.3))


def test_a_scan_with_infinities_and_nan_round_trips():
    store = registry.store()
    registry.get_message_class("sensor_msgs/msg/LaserScan")
    ranges = np.array([1.0, np.inf, -np.inf, np.nan, 0.25], dtype=np.float32)
    fields = (0.0, 6.28, 0.0175, 0.0, 0.2, 0.12, 3.5)
    packed = encode.laser_scan(5, b"base_scan", fields, ranges)
    decoded = store.deserialize(packed, "sensor_msgs/msg/LaserScan")
    assert decoded.header.frame_id == "base_scan"
    np.testing.assert_array_equal(decoded.ranges, ranges)
    assert len(decoded.intensities) == 0
    packer = encode.ScanPacker(b"base_scan", fields)
    assert packer(0, 5, ranges) == packed
    # a packer is used again and again: a shorter scan, as float64, not contiguous
    odd = np.array([2.0, 9.0, 0.5, 9.0, -np.inf], dtype=np.float64)[::2]
    assert packer(7, 8, odd) == encode.laser_scan(7 * NS + 8, b"base_scan", fields, odd)
    assert packer(0, 5, ranges) == packed


def driven_at_random(
    world_name: str, seed: int
) -> Iterator[tuple[SimRobot, build.RobotEncoder, int]]:
    """A world's first robot driven by random commands: it, its encoder and a stamp, 6 times."""
    sim = Simulation(load_world(resolve_world(world_name)))
    robot = sim.robots[0]
    encoder = build.RobotEncoder(robot)
    rng = np.random.default_rng(seed)
    for k in range(6):
        robot.robot.command(float(rng.uniform(-0.2, 0.2)), float(rng.uniform(-1.0, 1.0)))
        for _ in range(int(rng.integers(5, 60))):
            sim.step()
        yield robot, encoder, sim.now_ns + k * 10**9


@pytest.mark.parametrize("world_name", ["turtlebot3_world", "dolly_field"])
def test_the_sim_nodes_tick_packs_what_the_message_objects_serialize_to(world_name):
    # the tick's path: one stamp split once, odometry and the wheels adding their transforms
    # to one /tf message (odom first, then the wheels), joint states from the split stamp
    store = registry.store()
    tf_class = registry.get_message_class("tf2_msgs/msg/TFMessage")
    for robot, encoder, now in driven_at_random(world_name, seed=11):
        sec, nanosec = divmod(now, 10**9)
        values: list[object] = []
        odometry = encoder.odometry_at(sec, nanosec, values, True)
        assert store.serialize(build.odometry(robot, now)) == odometry
        assert encoder.odometry_at(sec, nanosec, [], False) == b""
        frames = encoder.odom_key
        transforms = list(build.odom_tf(robot, now).transforms)
        wheels = build.wheel_tf(robot, now)
        if wheels is not None:
            encoder.wheels_at(sec, nanosec, values)
            frames += encoder.wheel_key
            transforms += wheels.transforms
            joints = encoder.joint_states_at(sec, nanosec)
            assert store.serialize(build.joint_states(robot, now)) == joints
        packed = encode.tf_struct(frames).pack(encode.HEADER, len(frames), *values)
        assert store.serialize(tf_class(transforms=transforms)) == packed
        assert packed == build.tf_bytes(
            [encoder.odom_transform(robot.robot.odometry()), *encoder.wheel_transforms()], now
        )


@pytest.mark.parametrize("world_name", ["turtlebot3_world", "dolly_field"])
def test_one_tick_at_gives_what_the_odometry_and_wheel_calls_give_one_by_one(world_name):
    # the sim node's tick asks for a robot's odometry and wheels in one call: same messages,
    # same /tf values in the same order (odometry, then the wheels), b"" for no message
    store = registry.store()
    for robot, encoder, now in driven_at_random(world_name, seed=5):
        sec, nanosec = divmod(now, 10**9)
        one_by_one: list[object] = []
        odometry = encoder.odometry_at(sec, nanosec, one_by_one, True)
        encoder.wheels_at(sec, nanosec, one_by_one)
        joints = encoder.joint_states_at(sec, nanosec)
        together: list[object] = []
        both = encoder.tick_at(sec, nanosec, together, build.MESSAGE, build.MESSAGE)
        assert both == (odometry, joints)
        assert together == one_by_one
        assert store.serialize(build.odometry(robot, now)) == odometry
        if robot.robot.spec.model.joints:
            assert store.serialize(build.joint_states(robot, now)) == joints
        transforms_only: list[object] = []
        quiet = encoder.tick_at(sec, nanosec, transforms_only, build.TRANSFORM, build.TRANSFORM)
        assert quiet == (b"", b"")
        assert transforms_only == one_by_one
        assert encoder.tick_at(sec, nanosec, [], build.NOT_DUE, build.NOT_DUE) == (b"", b"")
