"""tf2_ros.Buffer (waiting, async, ``transform``) and tf2_geometry_msgs, in one process."""

from __future__ import annotations

import math
import subprocess
import sys
import threading

import numpy as np
import pytest
import tf2_geometry_msgs
import tf2_ros
from geometry_msgs.msg import (
    Point32,
    PointStamped,
    PolygonStamped,
    Pose,
    PoseStamped,
    PoseWithCovarianceStamped,
    Quaternion,
    Vector3Stamped,
)
from rclpy.duration import Duration
from rclpy.time import Time

from tests.tf2.support import close, transform, xyz, yaw


def flipped_buffer() -> tf2_ros.Buffer:
    """tf2_geometry_msgs' own test set-up: b is a's frame turned half round x, 1 m along x."""
    buffer = tf2_ros.Buffer()
    buffer.set_transform(transform("a", "b", (1.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0), 2.0), "t")
    return buffer


def stamped_in_a(message):
    message.header.stamp = Time(seconds=2.0).to_msg()
    message.header.frame_id = "a"
    return message


def test_buffer_transform_gives_exact_values_for_points_poses_and_covariances() -> None:
    buffer = flipped_buffer()
    found = buffer.lookup_transform("a", "b", Time(seconds=2.0).to_msg(), Duration(seconds=2))
    assert (found.transform.translation.x, found.transform.rotation.x) == (1.0, 1.0)
    point = stamped_in_a(PointStamped())
    point.point.x, point.point.y, point.point.z = 1.0, 2.0, 3.0
    out = buffer.transform(point, "b", new_type=PointStamped)
    assert (out.point.x, out.point.y, out.point.z) == (0.0, -2.0, -3.0)
    assert out.header.frame_id == "b"
    pose = stamped_in_a(PoseStamped())
    pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = 1.0, 2.0, 3.0
    pose.pose.orientation = Quaternion(w=0.0, x=1.0, y=0.0, z=0.0)
    out = buffer.transform(pose, "b")
    assert (out.pose.position.x, out.pose.position.y, out.pose.position.z) == (0.0, -2.0, -3.0)
    assert (out.pose.orientation.x, out.pose.orientation.w) == (0.0, 1.0)


def test_covariance_is_turned_with_the_pose() -> None:
    t = transform("a", "b", (1.0, 2.0, 3.0), (1.0, 0.0, 0.0, 0.0))
    pose = PoseWithCovarianceStamped()
    pose.pose.covariance = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0) * 6
    pose.pose.pose.position.x, pose.pose.pose.position.y = 1.0, 2.0
    pose.pose.pose.position.z = 3.0
    pose.pose.pose.orientation = Quaternion(w=0.0, x=1.0, y=0.0, z=0.0)
    out = tf2_geometry_msgs.do_transform_pose_with_covariance_stamped(pose, t)
    row_a, row_b = [1.0, -2.0, -3.0, 4.0, -5.0, -6.0], [-1.0, 2.0, 3.0, -4.0, 5.0, 6.0]
    assert np.array_equal(out.pose.covariance, np.array(row_a + row_b * 2 + row_a + row_b * 2))
    p, q = out.pose.pose.position, out.pose.pose.orientation
    assert (p.x, p.y, p.z, q.x, q.y, q.z, q.w) == (2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)


def test_vectors_turn_but_do_not_move_and_the_transform_is_left_alone() -> None:
    t = transform("a", "b", (1.0, 2.0, 3.0), (0.0, 1.0, 0.0, 0.0))  # half a turn about y
    vector = Vector3Stamped()
    vector.vector.x = 1.0
    out = tf2_geometry_msgs.do_transform_vector3(vector, t)
    assert (out.vector.x, out.vector.y, out.vector.z) == (-1.0, 0.0, 0.0)
    assert xyz(t) == (1.0, 2.0, 3.0)  # tf2_geometry_msgs zeroed it in place; rosl does not


def test_do_transform_pose_takes_a_pose_and_the_pose_stamped_older_code_passes() -> None:
    t = transform("map", "base", (1.0, 0.0, 0.0), yaw(math.pi / 2))
    pose = Pose()
    pose.position.x = 2.0
    out = tf2_geometry_msgs.do_transform_pose(pose, t)
    assert out.__msgtype__ == "geometry_msgs/msg/Pose"  # a Pose gives a Pose
    assert close((out.position.x, out.position.y), (1.0, 2.0))
    assert close((out.orientation.z, out.orientation.w), yaw(math.pi / 2)[2:])
    stamped = PoseStamped(pose=pose)
    out_stamped = tf2_geometry_msgs.do_transform_pose(stamped, t)
    assert out_stamped.header.frame_id == "map"
    assert close((out_stamped.pose.position.x, out_stamped.pose.position.y), (1.0, 2.0))
    assert tf2_geometry_msgs.do_transform_pose_stamped(stamped, t).pose == out_stamped.pose


def test_a_polygon_moves_point_by_point() -> None:
    t = transform("map", "base", (1.0, 0.0, 0.0), yaw(math.pi / 2))
    polygon = PolygonStamped()
    polygon.polygon.points = [Point32(x=1.0), Point32(y=1.0)]
    out = tf2_geometry_msgs.do_transform_polygon_stamped(polygon, t)
    assert [close((p.x, p.y), want, 1e-6) for p, want in
            zip(out.polygon.points, [(1.0, 1.0), (0.0, 0.0)], strict=True)] == [True, True]  # fmt: skip


def test_can_transform_waits_for_data_set_meanwhile_and_gives_up_after_the_timeout() -> None:
    buffer = tf2_ros.Buffer()
    assert buffer.can_transform("map", "base", Time(), Duration(seconds=0.2)) is False
    ok, why = buffer.can_transform("map", "base", Time(), Duration(seconds=0.1), True)
    assert not ok
    assert 'Invalid frame ID "map"' in why
    later = threading.Timer(0.2, lambda: buffer.set_transform(transform("map", "base"), "t"))
    later.start()
    try:
        assert buffer.can_transform("map", "base", Time(), Duration(seconds=30.0)) is True
    finally:
        later.cancel()
    with pytest.raises(tf2_ros.LookupException):
        buffer.lookup_transform("map", "nowhere", Time(), Duration(seconds=0.1))


def test_wait_for_transform_async_completes_when_the_data_comes() -> None:
    buffer = tf2_ros.Buffer()
    future = buffer.wait_for_transform_async("map", "base", Time())
    assert not future.done()
    buffer.set_transform(transform("odom", "base", (1.0, 0.0, 0.0)), "t")
    assert not future.done()  # base is there, map is not yet
    buffer.set_transform(transform("map", "odom", (0.0, 2.0, 0.0)), "t")
    assert future.done()
    assert xyz(future.result()) == (1.0, 2.0, 0.0)
    ready = buffer.wait_for_transform_async("map", "base", Time())
    assert ready.done()  # already possible: done at once


def test_buffer_transform_needs_no_import_of_tf2_geometry_msgs() -> None:
    code = (
        "import rosl, tf2_ros\n"
        "from geometry_msgs.msg import PointStamped, TransformStamped\n"
        "b = tf2_ros.Buffer()\n"
        "t = TransformStamped(child_frame_id='base')\n"
        "t.header.frame_id = 'map'\n"
        "t.transform.translation.x = 5.0\n"
        "b.set_transform_static(t, 'test')\n"
        "p = PointStamped()\n"
        "p.header.frame_id = 'base'\n"
        "print(b.transform(p, 'map').point.x)\n"
        "import sys\n"
        "print('tf2_geometry_msgs' in sys.modules)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=60, check=False)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["5.0", "False"]


def test_an_unregistered_type_is_a_type_exception() -> None:
    with pytest.raises(tf2_ros.TypeException, match="is not loaded or supported"):
        flipped_buffer().transform(Pose(), "b")


def test_a_clock_jumping_back_clears_the_buffer_as_a_looping_bag_needs() -> None:
    from rosl.node.clock import Clock, ClockType

    buffer = tf2_ros.Buffer()
    buffer.clock = Clock(clock_type=ClockType.ROS_TIME)
    buffer.clock.set_sim_time(True)
    buffer.clock.set_sim_now(30_000_000_000)
    for seconds in (29.0, 30.0):
        buffer.set_transform(transform("odom", "base", (seconds, 0.0, 0.0), seconds=seconds), "t")
    buffer.clock.set_sim_now(2_000_000_000)  # the bag starts over
    buffer.set_transform(transform("odom", "base", (2.0, 0.0, 0.0), seconds=2.0), "t")
    found = buffer.lookup_transform("odom", "base", Time())
    assert xyz(found) == (2.0, 0.0, 0.0)  # not refused as data from the past
    assert (found.header.stamp.sec, found.header.stamp.nanosec) == (2, 0)


def test_lookup_coroutines_finish_at_once_or_after_the_data_comes() -> None:
    now = Time(seconds=1234.5)
    sent = transform("foo", "bar", (42.0, -3.14, 0.0), seconds=1234.5)
    buffer = tf2_ros.Buffer()
    waiting = buffer.lookup_transform_async("foo", "bar", now)
    waiting_full = buffer.lookup_transform_full_async("foo", now, "bar", now, "foo")
    for coroutine in (waiting, waiting_full):
        coroutine.send(None)  # suspended: nothing to look up yet
    assert buffer.set_transform(sent, "unittest") is None
    for coroutine in (waiting, waiting_full, buffer.lookup_transform_async("foo", "bar", now)):
        with pytest.raises(StopIteration) as finished:
            coroutine.send(None)
        assert finished.value.value == sent
    assert buffer.lookup_transform("foo", "bar", now) == sent


def test_one_node_broadcasts_and_listens_and_static_frames_accumulate(ros) -> None:
    from rosl.executor import SingleThreadedExecutor

    node = ros.Node("test_broadcaster_listener")
    broadcaster = tf2_ros.TransformBroadcaster(node)
    static_broadcaster = tf2_ros.StaticTransformBroadcaster(node)
    listener = tf2_ros.TransformListener(buffer=tf2_ros.Buffer(), node=node)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    sent = transform("foo", "bar", (42.0, -3.14, 0.0), seconds=1.0)
    broadcaster.sendTransform(sent)
    found = listener.buffer.lookup_transform("foo", "bar", Time(seconds=1.0), Duration(seconds=30))
    assert found == sent
    listener.buffer = tf2_ros.Buffer()  # as tf2_ros's own test swaps it: the new one is fed
    static_broadcaster.sendTransform(transform("foo", "bar", (24.0, 0.0, 0.0), seconds=2.1))
    static_broadcaster.sendTransform(transform("foo", "qux", (10.0, 0.0, 0.0), seconds=3.1))
    qux = listener.buffer.lookup_transform("foo", "qux", Time(seconds=3.5), Duration(seconds=30))
    assert (xyz(qux), qux.header.stamp.sec, qux.header.stamp.nanosec) == ((10.0, 0.0, 0.0), 3,
                                                                           500_000_000)  # fmt: skip
    # the second message repeated the first static frame: a listener joining now gets both
    late = tf2_ros.Buffer()
    tf2_ros.TransformListener(late, ros.Node("late_listener"))
    bar = late.lookup_transform("foo", "bar", Time(), Duration(seconds=30))
    assert xyz(bar) == (24.0, 0.0, 0.0)
    assert late.can_transform("foo", "qux", Time(), Duration(seconds=30))
    node.destroy_node()


def test_a_listener_without_a_node_makes_its_own_and_unregister_stops_it(ros) -> None:
    talker = ros.Node("talker")
    static_broadcaster = tf2_ros.StaticTransformBroadcaster(talker)
    buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(buffer)
    assert listener.node.get_name().startswith("transform_listener_impl_")
    assert listener.node.get_parameter("use_sim_time").value is False
    static_broadcaster.sendTransform(transform("map", "odom", (1.0, 0.0, 0.0)))
    assert xyz(buffer.lookup_transform("map", "odom", Time(), Duration(seconds=30))) == (
        1.0, 0.0, 0.0)  # fmt: skip
    listener.unregister()
    static_broadcaster.sendTransform(transform("map", "elsewhere"))
    assert not buffer.can_transform("map", "elsewhere", Time(), Duration(seconds=0.5))
