"""``rosl sim`` on the real bus: topics and types, latched statics, the TF tree, /cmd_vel."""

from __future__ import annotations

import itertools
import math
import re
import time
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.launch.support import Rosl

TOPICS = {
    "/clock": "rosgraph_msgs/msg/Clock",
    "/cmd_vel": "geometry_msgs/msg/Twist",
    "/joint_states": "sensor_msgs/msg/JointState",
    "/odom": "nav_msgs/msg/Odometry",
    "/robot_description": "std_msgs/msg/String",
    "/scan": "sensor_msgs/msg/LaserScan",
    "/tf": "tf2_msgs/msg/TFMessage",
    "/tf_static": "tf2_msgs/msg/TFMessage",
}
TREE = {
    "base_footprint": "odom",
    "base_link": "base_footprint",
    "base_scan": "base_link",
    "imu_link": "base_link",
    "wheel_left_link": "base_link",
    "wheel_right_link": "base_link",
}


class Inbox:
    """The messages a node in the test process received, per topic."""

    def __init__(self, ros: Any, node: Any) -> None:
        self.ros = ros
        self.node = node
        self.got: dict[str, list[Any]] = {}

    def listen(self, msg_type: Any, topic: str, qos: Any = 10) -> None:
        self.node.create_subscription(
            msg_type, topic, lambda m: self.got.setdefault(topic, []).append(m), qos
        )

    def spin_until(self, done: Callable[[], bool], timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        while not done() and time.monotonic() < deadline:
            self.ros.spin_once(self.node, timeout_sec=0.05)
        return done()

    def latest(self, topic: str) -> Any:
        return self.got[topic][-1]


def odom_x(inbox: Inbox) -> float:
    return inbox.latest("/odom").pose.pose.position.x


@pytest.mark.slow
def test_a_paced_sim_publishes_its_topics_tf_tree_and_follows_cmd_vel(
    rosl: Rosl, ros: Any, tmp_path: Path
) -> None:
    from geometry_msgs.msg import Twist  # noqa: F401 - the type must resolve in this process
    from nav_msgs.msg import Odometry
    from rosbags.highlevel import AnyReader
    from rosgraph_msgs.msg import Clock
    from sensor_msgs.msg import JointState, LaserScan
    from std_msgs.msg import String
    from tf2_msgs.msg import TFMessage

    from rosl.bag.selection import RECORDER_NODE
    from rosl.graph.records import SUBSCRIPTION
    from rosl.node.qos import DurabilityPolicy, QoSProfile, qos_profile_sensor_data

    bag = tmp_path / "late_recording"
    sim = rosl.start("sim", "empty", "--real-time-factor", "2", "--headless")
    inbox = Inbox(ros, ros.Node("sim_probe"))
    for msg_type, topic in [(Clock, "/clock"), (Odometry, "/odom"), (JointState, "/joint_states")]:
        inbox.listen(msg_type, topic)
    inbox.listen(TFMessage, "/tf")
    inbox.listen(LaserScan, "/scan", qos_profile_sensor_data)
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    inbox.listen(String, "/robot_description", latched)
    everything = ["/clock", "/odom", "/joint_states", "/tf", "/scan", "/robot_description"]
    assert inbox.spin_until(lambda: all(t in inbox.got for t in everything), 60.0), (
        sorted(inbox.got),
        sim.both(),
    )

    # a late subscriber still gets /tf_static (transient local), sent once at the start
    inbox.spin_until(lambda: False, 0.5)
    inbox.listen(TFMessage, "/tf_static", latched)
    assert inbox.spin_until(lambda: "/tf_static" in inbox.got, 30.0), sim.both()
    static = {
        t.child_frame_id: t.header.frame_id for m in inbox.got["/tf_static"] for t in m.transforms
    }
    for child in ("base_link", "base_scan", "imu_link"):
        assert static[child] == TREE[child]

    # so does a recorder started late: the bag holds the statics and the robot's description
    recorder = rosl.start("bag", "record", "/tf_static", "/robot_description", "-o", str(bag))
    graph = inbox.node.participant.graph

    def recorded(topic: str) -> int:
        found = [e for n, e in graph.endpoints(SUBSCRIPTION, topic) if n.name == RECORDER_NODE]
        return int(found[0].stats.get("received", 0)) if found else 0

    latched_topics = ("/tf_static", "/robot_description")
    assert inbox.spin_until(lambda: all(recorded(t) >= 1 for t in latched_topics), 30.0), (
        recorder.both()
    )
    assert recorder.interrupt() == 0, recorder.both()
    with AnyReader([bag]) as reader:
        kept = {c.topic: c.msgcount for c in reader.connections}
    assert kept == {"/tf_static": 1, "/robot_description": 1}, kept

    odom = inbox.latest("/odom")
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_footprint")
    scan = inbox.latest("/scan")
    assert scan.header.frame_id == "base_scan"
    assert len(scan.ranges) == 360
    assert all(math.isinf(r) and r > 0 for r in scan.ranges)  # the empty world
    joints = inbox.latest("/joint_states")
    assert list(joints.name) == ["wheel_left_joint", "wheel_right_joint"]
    assert "<robot" in inbox.latest("/robot_description").data
    clock_ns = [c.clock.sec * 10**9 + c.clock.nanosec for c in inbox.got["/clock"]]
    assert clock_ns == sorted(clock_ns)

    code, out, _ = rosl.run("topic", "list", "-t")
    assert code == 0
    listed = dict(re.findall(r"^(\S+) \[(\S+)\]$", out, re.MULTILINE))
    for topic, type_name in TOPICS.items():
        assert listed.get(topic) == type_name, out

    code, out, err = rosl.run("tf", "frames", "--dot", "-t", "1.5")
    assert code == 0, err
    edges = dict((c, p) for p, c in re.findall(r'^"([^"]+)" -> "([^"]+)"\[', out, re.MULTILINE))
    for child, parent in TREE.items():
        assert edges.get(child) == parent, out

    # /cmd_vel from `rosl topic pub` drives it
    start_x = odom_x(inbox)
    code, _, err = rosl.run(
        "topic", "pub", "-t", "5", "-r", "10", "/cmd_vel", "geometry_msgs/msg/Twist",
        "{linear: {x: 0.2}}",
    )  # fmt: skip
    assert code == 0, err
    assert inbox.spin_until(lambda: odom_x(inbox) > start_x + 0.05, 30.0), odom_x(inbox)

    # NaN on the bus: one warning, the last good command stays, the sim keeps running
    code, _, err = rosl.run(
        "topic", "pub", "-t", "3", "-r", "10", "/cmd_vel", "geometry_msgs/msg/Twist",
        "{linear: {x: .nan}, angular: {z: 0.0}}",
    )  # fmt: skip
    assert code == 0, err
    assert sim.wait_for("non-finite", "err", timeout=30.0), sim.both()
    moving_x = odom_x(inbox)
    inbox.spin_until(lambda: odom_x(inbox) > moving_x + 0.05, 30.0)
    latest = inbox.latest("/odom")
    assert math.isfinite(latest.pose.pose.position.x)
    assert latest.twist.twist.linear.x == pytest.approx(0.2)
    assert sim.child.poll() is None

    assert sim.interrupt() == 0, sim.both()
    warnings = [line for line in sim.lines("err") if "WARN" in line]
    assert len(warnings) == 1, sim.both()
    assert "ignored a cmd_vel with non-finite values" in warnings[0]
    assert "Traceback" not in sim.text("err")
    assert any("non-finite values: 3 time(s)" in line for line in sim.lines("out")), sim.both()


def test_rosl_sim_stops_after_its_duration_and_prints_a_summary(rosl: Rosl) -> None:
    code, out, err = rosl.run(
        "sim", "turtlebot3_world", "--real-time-factor", "20", "--duration", "1", "--headless",
        timeout=60.0,
    )  # fmt: skip
    assert code == 0, err
    assert re.search(r"simulated 1\.00 s of turtlebot3_world", out), out
    assert re.search(r"burger: drove 0\.00 m, .* no collisions; ends at x=-2\.00 y=-0\.50", out)


@pytest.mark.parametrize(("rate", "every_ms"), [(None, 100), (1000.0, 10)], ids=["default", "fast"])
def test_clock_goes_out_at_its_rate_and_with_every_steps_data(
    rosl: Rosl, tmp_path: Path, rate: float | None, every_ms: int
) -> None:
    from tests.sim.conftest import read_bag, stamp_ns

    bag = tmp_path / "run"
    chosen = [] if rate is None else ["--clock-rate", str(rate)]
    code, out, err = rosl.run(
        "sim", "empty", "--fast", "--startup-timeout", "0.1", "--duration", "2", "--headless",
        "--record", str(bag), *chosen, timeout=120.0,
    )  # fmt: skip
    assert code == 0, out + err
    recorded = read_bag(bag, "/clock", "/odom", "/scan")
    clock = [m.clock.sec * 10**9 + m.clock.nanosec for topic, _, m in recorded if topic == "/clock"]
    data = {stamp_ns(m.header) for topic, _, m in recorded if topic != "/clock"}
    assert clock == sorted(clock)
    assert data
    assert data <= set(clock)  # a subscriber's time is never behind a stamp it has received
    gaps = {b - a for a, b in itertools.pairwise(clock)}
    assert max(gaps) <= every_ms * 1_000_000
    if rate is None:  # 10 Hz and the 30 Hz odometry's steps: far fewer than the 200 steps
        assert 60 <= len(clock) < 120, clock
    else:  # at or above the 100 Hz physics: every step
        assert clock == list(range(0, 2 * 10**9 + 1, 10_000_000))


def test_flat_out_the_batches_bring_every_message_of_every_firing(ros: Any) -> None:
    # paced far above what the machine can do, the loop never waits: the topics go out in
    # batches every few milliseconds of wall time (several datagrams when a batch is full);
    # a subscriber still gets each firing's message once, in order, clock with all the data
    from rosl.idl.registry import get_message_class
    from rosl.node.qos import QoSProfile, ReliabilityPolicy
    from rosl.sim.options import SimOptions
    from rosl.sim.sim_node import SimNode
    from rosl.sim.simulation import Schedule, Simulation
    from rosl.sim.worldfile import load_world, resolve_world

    inbox = Inbox(ros, ros.Node("listener"))
    for topic in ("/clock", "/odom", "/joint_states", "/tf"):
        inbox.listen(get_message_class(TOPICS[topic]), topic, 100_000)
    best_effort = QoSProfile(depth=100_000, reliability=ReliabilityPolicy.BEST_EFFORT)
    inbox.listen(get_message_class(TOPICS["/scan"]), "/scan", best_effort)  # as sensor data
    sim = Simulation(load_world(resolve_world("turtlebot3_world")))
    options = SimOptions(real_time_factor=1e9, duration=20.0, headless=True)
    runner = SimNode(sim, ros.Node("sim"), options, publish_all=True)
    runner.run()

    def expected(rate: float) -> list[int]:  # the firings on the 10 ms steps up to 20 s
        schedule, out = Schedule(rate), []
        for now in range(0, 20 * 10**9 + 1, sim.step_ns):
            if schedule.due(now):
                schedule.fire(now)
                out.append(now)
        return out

    odometry, scans = expected(30.0), expected(5.0)
    assert inbox.spin_until(lambda: len(inbox.got.get("/clock", [])) >= len(odometry), 60.0)
    assert inbox.spin_until(
        lambda: all(len(inbox.got.get(t, [])) >= len(odometry) for t in ("/odom", "/tf")), 60.0
    )
    stamps = {
        topic: [m.header.stamp.sec * 10**9 + m.header.stamp.nanosec for m in inbox.got[topic]]
        for topic in ("/odom", "/joint_states", "/scan")
    }
    assert stamps["/odom"] == odometry
    assert stamps["/joint_states"] == odometry
    assert stamps["/scan"] == scans
    tf = [m.transforms[0].header.stamp for m in inbox.got["/tf"]]
    assert [s.sec * 10**9 + s.nanosec for s in tf] == odometry
    clock = [m.clock.sec * 10**9 + m.clock.nanosec for m in inbox.got["/clock"]]
    assert clock == sorted(set(clock))
    assert set(odometry) <= set(clock)
    assert clock == sorted(set(odometry) | set(expected(10.0)))
