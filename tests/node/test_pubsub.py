"""Publishers and subscriptions across processes, and the QoS words that change behaviour."""

from __future__ import annotations

import re
import threading

import pytest

from tests.node.helpers import spin_for, spin_until

ECHO = """
import rosl
from std_msgs.msg import String

rosl.init()
node = rosl.Node("echo")
back = node.create_publisher(String, "pong", 10)

def on_ping(msg):
    print("heard:", msg.data, flush=True)
    back.publish(String(data="echo " + msg.data))

node.create_subscription(String, "ping", on_ping, 10)
print("ready", flush=True)
rosl.spin(node)
"""


def test_a_string_crosses_to_another_process_and_its_echo_comes_back(ros, spawn):
    from std_msgs.msg import String

    child = spawn(ECHO)
    child.expect("^ready$")
    node = ros.Node("pinger")
    pub = node.create_publisher(String, "ping", 10)
    replies: list[str] = []
    node.create_subscription(String, "pong", lambda m: replies.append(m.data), 10)
    text = "hello wörld ✓ 123"

    assert spin_until(
        node, lambda: bool(replies), 20.0, each=lambda: pub.publish(String(data=text))
    )
    assert replies[0] == f"echo {text}"
    child.expect(f"^heard: {text}$")


LASER = """
import math
import rosl
from sensor_msgs.msg import LaserScan
from geometry_msgs.msg import Twist

rosl.init()
node = rosl.Node("sensors")
scan_pub = node.create_publisher(LaserScan, "scan", 10)
twist_pub = node.create_publisher(Twist, "cmd_vel", 10)
scan = LaserScan()
scan.header.frame_id = "laser_frame"
scan.header.stamp.sec = 12
scan.header.stamp.nanosec = 345
scan.angle_min = -1.5
scan.angle_max = 1.5
scan.angle_increment = 0.25
scan.range_min = 0.125
scan.range_max = 30.0
scan.ranges = [0.5, 1.25, 2.0, 3.75, 10.5, 0.0, 29.875]
scan.intensities = [1.0, 2.0, 4.0]
twist = Twist()
twist.linear.x = 1.5
twist.linear.y = -0.25
twist.angular.z = -0.75

def tick():
    scan_pub.publish(scan)
    twist_pub.publish(twist)

node.create_timer(0.05, tick)
print("ready", flush=True)
rosl.spin(node)
"""


def test_a_laser_scan_with_arrays_and_a_nested_twist_arrive_with_equal_values(ros, spawn):
    from geometry_msgs.msg import Twist
    from sensor_msgs.msg import LaserScan

    child = spawn(LASER)
    child.expect("^ready$")
    node = ros.Node("listener")
    scans: list[LaserScan] = []
    twists: list[Twist] = []
    node.create_subscription(LaserScan, "scan", scans.append, 10)
    node.create_subscription(Twist, "/cmd_vel", twists.append, 10)

    assert spin_until(node, lambda: bool(scans) and bool(twists), 20.0)
    scan = scans[0]
    assert scan.header.frame_id == "laser_frame"
    assert (scan.header.stamp.sec, scan.header.stamp.nanosec) == (12, 345)
    assert (scan.angle_min, scan.angle_max, scan.angle_increment) == (-1.5, 1.5, 0.25)
    assert (scan.range_min, scan.range_max) == (0.125, 30.0)
    assert [float(r) for r in scan.ranges] == [0.5, 1.25, 2.0, 3.75, 10.5, 0.0, 29.875]
    assert [float(i) for i in scan.intensities] == [1.0, 2.0, 4.0]
    twist = twists[0]
    assert (twist.linear.x, twist.linear.y, twist.linear.z) == (1.5, -0.25, 0.0)
    assert (twist.angular.x, twist.angular.y, twist.angular.z) == (0.0, 0.0, -0.75)
    expected = Twist()
    expected.linear.x, expected.linear.y, expected.angular.z = 1.5, -0.25, -0.75
    assert twist == expected


def test_a_node_receives_its_own_messages_on_a_topic_it_publishes(ros):
    from std_msgs.msg import Int32

    node = ros.Node("self_talker")
    pub = node.create_publisher(Int32, "loop", 10)
    got: list[int] = []
    node.create_subscription(Int32, "loop", lambda m: got.append(m.data), 10)

    assert spin_until(node, lambda: bool(got), 5.0, each=lambda: pub.publish(Int32(data=41)))
    assert set(got) == {41}


def test_a_message_sent_as_bytes_is_received_as_the_message(ros):
    from std_msgs.msg import String

    from rosl.idl import registry

    node = ros.Node("raw_sender")
    pub = node.create_publisher(String, "raw", 10)
    got: list[str] = []
    node.create_subscription(String, "raw", lambda m: got.append(m.data), 10)
    data = registry.store().serialize(String(data="pre-serialized"))

    assert spin_until(node, lambda: bool(got), 5.0, each=lambda: pub.publish(data))
    assert got[0] == "pre-serialized"


# --- QoS -------------------------------------------------------------------------------------

LATCHED = """
import time
import rosl
from std_msgs.msg import Int32
from rosl.node.qos import DurabilityPolicy, QoSProfile

rosl.init()
node = rosl.Node("latcher")
qos = QoSProfile(depth=3, durability=DurabilityPolicy.TRANSIENT_LOCAL)
pub = node.create_publisher(Int32, "latched", qos)
for i in range(1, 6):
    pub.publish(Int32(data=i))
print("published", flush=True)
seen = []

def tick():
    # once a subscriber shows up, go on with live messages (6) after a short pause
    if pub.get_subscription_count() > 0:
        seen.append(time.monotonic())
        if time.monotonic() - seen[0] > 0.5:
            pub.publish(Int32(data=6))

node.create_timer(0.1, tick)
rosl.spin(node)
"""


def _late_subscriber(ros, spawn, durability, then=0.2):
    from std_msgs.msg import Int32

    from rosl.node.qos import QoSProfile

    child = spawn(LATCHED)
    child.expect("^published$")
    node = ros.Node("late_listener")
    got: list[int] = []
    qos = QoSProfile(depth=10, durability=durability)
    node.create_subscription(Int32, "latched", lambda m: got.append(m.data), qos)
    # wait for the live message 6 (sent ~0.5 s after the subscription is seen), then a bit more
    assert spin_until(node, lambda: 6 in got, 20.0), f"no live message arrived: {got}"
    spin_for(node, then)
    return got


def test_a_late_transient_local_subscriber_gets_the_last_depth_messages_in_order(ros, spawn):
    from rosl.node.qos import DurabilityPolicy

    got = _late_subscriber(ros, spawn, DurabilityPolicy.TRANSIENT_LOCAL)
    assert got[:3] == [3, 4, 5], got
    assert set(got[3:]) == {6}, got


def test_a_late_subscriber_asks_for_history_twice_and_gets_it_once(ros, spawn):
    # the ask is one datagram: it goes again a second later (HISTORY_ASKED_AGAIN_S), and the
    # replay that answers it again is not delivered again
    from rosl.node.qos import DurabilityPolicy
    from rosl.node.subscription import HISTORY_ASKED_AGAIN_S

    got = _late_subscriber(ros, spawn, DurabilityPolicy.TRANSIENT_LOCAL, 2 * HISTORY_ASKED_AGAIN_S)
    assert got[:3] == [3, 4, 5], got
    assert set(got[3:]) == {6}, got


def test_a_late_volatile_subscriber_gets_none_of_the_old_messages(ros, spawn):
    from rosl.node.qos import DurabilityPolicy

    got = _late_subscriber(ros, spawn, DurabilityPolicy.VOLATILE)
    assert got, "the subscription heard nothing at all"
    assert set(got) == {6}, got


def test_publishing_never_blocks_when_nobody_subscribes(ros):
    from std_msgs.msg import String

    from rosl.node.qos import (
        DurabilityPolicy,
        QoSProfile,
        ReliabilityPolicy,
        qos_profile_sensor_data,
    )

    node = ros.Node("lonely")
    publishers = [
        node.create_publisher(String, "nobody_reliable", QoSProfile(depth=1)),
        node.create_publisher(
            String,
            "nobody_latched",
            QoSProfile(
                depth=3,
                reliability=ReliabilityPolicy.RELIABLE,
                durability=DurabilityPolicy.TRANSIENT_LOCAL,
            ),
        ),
        node.create_publisher(String, "nobody_sensor", qos_profile_sensor_data),
    ]
    sent = [0]

    def publish_many() -> None:
        for i in range(500):
            for pub in publishers:
                pub.publish(String(data=f"message {i}" * 20))
                sent[0] += 1

    worker = threading.Thread(target=publish_many, daemon=True)
    worker.start()
    worker.join(timeout=20)
    assert not worker.is_alive(), f"publish blocked after {sent[0]} messages"
    assert sent[0] == 1500
    assert all(p.get_subscription_count() == 0 for p in publishers)


def test_publishing_a_message_of_the_wrong_type_names_both_types(ros):
    from std_msgs.msg import Int32, String

    node = ros.Node("typo")
    pub = node.create_publisher(String, "typed", 10)
    with pytest.raises(TypeError) as err:
        pub.publish(Int32(data=1))
    assert "std_msgs/msg/String" in str(err.value)
    assert "std_msgs/msg/Int32" in str(err.value)


def test_a_callback_taking_two_arguments_also_gets_the_message_info(ros):
    from std_msgs.msg import Int32

    node = ros.Node("info_reader")
    pub = node.create_publisher(Int32, "with_info", 10)
    got: list[tuple[int, dict]] = []
    node.create_subscription(Int32, "with_info", lambda m, info: got.append((m.data, info)), 10)

    assert spin_until(node, lambda: bool(got), 5.0, each=lambda: pub.publish(Int32(data=5)))
    data, info = got[0]
    assert data == 5
    assert info["publication_sequence_number"] >= 1
    assert info["reception_sequence_number"] == 1
    assert info["received_timestamp"] >= info["source_timestamp"] > 0


def test_a_destroyed_subscription_receives_nothing_more(ros):
    from std_msgs.msg import Int32

    node = ros.Node("quitter")
    pub = node.create_publisher(Int32, "stop_me", 10)
    got: list[int] = []
    sub = node.create_subscription(Int32, "stop_me", lambda m: got.append(m.data), 10)
    assert spin_until(node, lambda: bool(got), 5.0, each=lambda: pub.publish(Int32(data=1)))

    assert node.destroy_subscription(sub)
    spin_for(node, 0.1)
    count = len(got)
    for _ in range(5):
        pub.publish(Int32(data=2))
        spin_for(node, 0.05)
    assert len(got) == count
    assert 2 not in got


MISMATCHED = """
import rosl
from std_msgs.msg import Int32

rosl.init()
node = rosl.Node("int_talker")
pub = node.create_publisher(Int32, "mixed", 10)
node.create_timer(0.05, lambda: pub.publish(Int32(data=7)))
print("ready", flush=True)
rosl.spin(node)
"""


def test_a_message_of_another_type_is_dropped_with_one_warning_and_never_misdecoded(
    ros, spawn, capfd
):
    from std_msgs.msg import String

    child = spawn(MISMATCHED)
    child.expect("^ready$")
    node = ros.Node("str_listener")
    got: list[str] = []
    sub = node.create_subscription(String, "mixed", lambda m: got.append(m.data), 10)

    assert spin_until(node, lambda: sub.mismatched >= 3, 20.0)
    assert got == []
    err = capfd.readouterr().err
    warnings = re.findall(
        r"^\[WARN\] .*\[str_listener\]: subscription on /mixed expects .*$", err, re.M
    )
    assert len(warnings) == 1, err
    assert "std_msgs/msg/String" in warnings[0]


LISTENER = """
import rosl
from std_msgs.msg import String

rosl.init()
node = rosl.Node("gap_listener")
node.create_subscription(String, "gaps", lambda msg: print("heard", msg.data, flush=True), 10)
print("ready", flush=True)
rosl.spin(node)
"""


def test_a_subscriber_logs_the_messages_it_lost_to_sequence_gaps(ros, spawn):
    from std_msgs.msg import String

    from rosl.bus.header import Kind

    child = spawn(LISTENER)
    child.expect("^ready$")
    node = ros.Node("gappy_talker")
    pub = node.create_publisher(String, "gaps", 10)
    assert pub.wait_for_subscribers(1, 10.0) == 1
    data = pub._store.serialize(String(data="x"))
    for seq in (1, 2, 5):  # 3 and 4 never go out: what a full socket buffer does
        pub._writer.send(data, kind=Kind.DATA, seq=seq)
    child.expect("^heard x$")
    child.expect("^heard x$")
    child.expect("^heard x$")
    warning = child.expect(r"^.*lost \d+ message\(s\) on /gaps.*$", stream="err").group(0)
    assert "[WARN]" in warning
    assert "[gap_listener]" in warning
    assert "lost 2 message(s) on /gaps" in warning
    _, err = child.stop()
    assert err.count("lost ") == 1  # once, not once per message


BURST = """
import rosl
from std_msgs.msg import String

rosl.init()
node = rosl.Node("burst_talker")
pub = node.create_publisher(String, "burst", 1000)
assert pub.wait_for_subscribers(1, 10.0) == 1
for n in range(500):
    pub.publish(String(data=str(n)))
print("sent, coalescing:", pub._writer.batch is not None, flush=True)
rosl.spin(node)
"""


def test_a_coalescing_publisher_delivers_every_message_in_order(ros, spawn):
    from std_msgs.msg import String

    node = ros.Node("burst_listener")
    heard: list[str] = []
    node.create_subscription(String, "burst", lambda m: heard.append(m.data), 1000)
    child = spawn(BURST, env={"ROSL_COALESCE": "1"})
    child.expect("^sent, coalescing: True$")
    assert spin_until(node, lambda: len(heard) >= 500, 10.0), len(heard)
    assert heard == [str(n) for n in range(500)]
    assert node.subscriptions[0].lost == 0


def _echoed_publisher(ros, spawn, name):
    """A child echoing "ping", a node ``name`` publishing on it, a first message heard."""
    from std_msgs.msg import String

    child = spawn(ECHO)  # prints what it hears on "ping"
    child.expect("^ready$")
    node = ros.Node(name)
    pub = node.create_publisher(String, "ping", 10)
    assert spin_until(node, lambda: pub.get_subscription_count() > 0, 20.0)
    pub.publish(String(data="probe"))  # a sent message: the child hears this one
    child.expect("^heard: probe$")
    return child, node, pub


def test_a_held_publisher_sends_nothing_until_flushed_then_everything_in_order(ros, spawn):
    from std_msgs.msg import String

    child, node, pub = _echoed_publisher(ros, spawn, "holder")
    pub.hold_until_flush()
    for k in range(5):
        pub.publish(String(data=f"held {k}"))
    spin_for(node, 1.0)
    pub.publish(String(data="after"))  # in the same batch: still nothing sent
    spin_for(node, 1.0)
    assert child.count("^heard: (held|after)") == 0

    pub.flush()

    for k in range(5):
        child.expect(f"^heard: held {k}$")
    child.expect("^heard: after$")


def test_a_held_publisher_with_a_bigger_batch_bound_sends_over_16_kb_at_the_flush(ros, spawn):
    # the simulator holds ~17 KB of odometry per flush: above the default 16 KB bound, which
    # would send part of it before the flush; with a 60 KB bound it all waits for the flush
    from std_msgs.msg import String

    from rosl.idl import registry

    child, node, pub = _echoed_publisher(ros, spawn, "big_holder")
    pub.hold_until_flush(60000)
    store = registry.store()
    count = 8  # 8 x 3 KB: 24 KB, over the default bound
    pub.publish_all(
        [bytes(store.serialize(String(data=f"big {k} " + "x" * 3000))) for k in range(count)]
    )
    spin_for(node, 0.5)
    assert child.count("^heard: big") == 0  # nothing went before the flush
    pub.flush()
    for k in range(count):
        child.expect(f"^heard: big {k} x{{3000}}$")
    assert pub.record().stats["sent"] == count + 1


@pytest.mark.parametrize("held", [True, False], ids=["held", "plain"])
def test_publish_all_sends_serialized_messages_in_order_as_publish_would(ros, spawn, held):
    from std_msgs.msg import String

    from rosl.idl import registry

    child, node, pub = _echoed_publisher(ros, spawn, "queuer")
    if held:
        pub.hold_until_flush()
    store = registry.store()
    pub.publish_all([bytes(store.serialize(String(data=f"queued {k}"))) for k in range(5)])
    pub.publish_all([])  # nothing to send: nothing changes
    if held:
        spin_for(node, 1.0)
        assert child.count("^heard: queued") == 0  # held until the flush
        pub.flush()
    for k in range(5):
        child.expect(f"^heard: queued {k}$")
    assert pub.record().stats["sent"] == 6
