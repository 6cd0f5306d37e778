"""Which subscriptions hold a shared-memory publisher back (see rosl.bus.shm_ring).

In one process, on the test's domain: a reliable subscription holds its topic until it is
destroyed; a best-effort subscription never holds, and a best-effort publisher never waits.
"""

from __future__ import annotations

import sys

from rosl.bus.header import topic_hash
from tests.conftest import wait_until
from tests.node.helpers import spin_until

BIG = "x" * 40_000  # above the 16 KiB threshold: these go through shared memory


def test_a_reliable_subscription_holds_its_topic_until_it_is_destroyed(ros):
    from std_msgs.msg import String

    node = ros.Node("hold_reliable")
    heard: list[int] = []
    sub = node.create_subscription(String, "held", lambda m: heard.append(len(m.data)), 10)
    pub = node.create_publisher(String, "held", 10)
    held = topic_hash("/held")
    reader = node.participant.reader
    assert wait_until(lambda: pub.get_subscription_count() == 1, 15.0)
    assert sub.holding
    assert held in reader.held
    pub.publish(String(data=BIG))
    assert spin_until(node, lambda: heard == [len(BIG)], 15.0)
    assert pub._writer.shm_sent == 1, "the message did not take shared memory"

    node.destroy_subscription(sub)
    assert held not in reader.held


def test_topic_echo_never_holds_the_publisher_it_shows(ros, spawn):
    from std_msgs.msg import UInt8MultiArray

    node = ros.Node("hold_echoed")
    pub = node.create_publisher(UInt8MultiArray, "echoed", 10)  # reliable: echo matches it
    echo = spawn.command(
        [sys.executable, "-m", "rosl", "topic", "echo", "/echoed", "--field", "layout.data_offset"]
    )
    message = UInt8MultiArray(data=bytes(40_000))
    assert spin_until(
        node, lambda: echo.count("^0$") > 0, 30.0, each=lambda: pub.publish(message)
    ), echo.text
    assert pub._writer.shm_sent > 0, "the messages did not take shared memory"
    rings = list(pub._writer.shm._rings.values())
    assert rings
    assert [ring._holders() for ring in rings] == [[]] * len(rings)


def test_best_effort_subscriptions_never_hold_and_best_effort_publishers_never_wait(ros):
    from std_msgs.msg import String

    from rosl.node.qos import QoSProfile, ReliabilityPolicy, qos_profile_sensor_data

    node = ros.Node("hold_best_effort")
    sub = node.create_subscription(String, "loose", lambda m: None, qos_profile_sensor_data)
    assert not sub.holding
    assert topic_hash("/loose") not in node.participant.reader.held
    careless = node.create_publisher(
        String, "loose", QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
    )
    careful = node.create_publisher(String, "held_too", 10)
    assert not careless._writer.shm_hold
    assert careful._writer.shm_hold
