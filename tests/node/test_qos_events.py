"""QoS as ROS 2 means it, between processes: incompatible pairs, deadline, lifespan, liveliness
and message loss, with the event callbacks of rclpy.qos_event / rclpy.event_handler."""

from __future__ import annotations

import itertools
import os
import re
import signal
import subprocess
import sys
import time

import pytest

from tests.conftest import wait_until
from tests.node.qos_programs import LISTENER, ONE_PROCESS, RUN_AS_RCLPY, TALKER, start, write

BOUND = 30.0  # seconds: only a broken implementation takes this long

INCOMPATIBLE = [
    ("RELIABILITY", {"reliability": "BEST_EFFORT"}, {"reliability": "RELIABLE"}),
    ("DURABILITY", {"durability": "VOLATILE"}, {"durability": "TRANSIENT_LOCAL"}),
    ("DEADLINE", {}, {"deadline": 1.0}),
    ("LIVELINESS", {"liveliness": "AUTOMATIC"}, {"liveliness": "MANUAL_BY_TOPIC"}),
]


@pytest.mark.parametrize(("policy", "offered", "requested"), INCOMPATIBLE)
def test_an_incompatible_pair_exchanges_nothing_and_both_sides_are_told(
    spawn, tmp_path, policy, offered, requested
):
    told = start(spawn, tmp_path, LISTENER, "told", requested)
    warned = start(spawn, tmp_path, LISTENER, "warned", {**requested, "callbacks": False})
    control = start(spawn, tmp_path, LISTENER, "control", {"reliability": "BEST_EFFORT"})
    for listener in (told, warned, control):  # they hear of the publisher before it publishes
        listener.expect(r"^ready$", timeout=BOUND)
    talker = start(spawn, tmp_path, TALKER, "talker", offered)

    talker.expect(rf"^offered incompatible total=\d+ change=\d+ policy={policy}$", timeout=BOUND)
    told.expect(rf"^requested incompatible total=1 change=1 policy={policy}$", timeout=BOUND)
    warned.expect(
        r"New publisher discovered on topic '/qos_chatter', offering incompatible QoS\. "
        rf"No messages will be received from it\. Last incompatible policy: {policy}",
        stream="err",
        timeout=BOUND,
    )
    for _ in range(5):  # the compatible subscription hears the talker all along
        control.expect(r"^heard on qos_chatter: msg \d+$", timeout=BOUND)
    while int(talker.expect(r"^published (\d+)$", timeout=BOUND).group(1)) < 20:
        pass  # twenty messages were sent

    assert told.count(r"^heard") == 0
    assert warned.count(r"^heard") == 0


def test_a_publisher_without_callback_warns_of_an_incompatible_subscription(spawn, tmp_path):
    talker = start(
        spawn, tmp_path, TALKER, "talker", {"callbacks": False, "reliability": "BEST_EFFORT"}
    )
    start(spawn, tmp_path, LISTENER, "listener", {"reliability": "RELIABLE"})

    talker.expect(
        r"New subscription discovered on topic '/qos_chatter', requesting incompatible QoS\. "
        r"No messages will be sent to it\. Last incompatible policy: RELIABILITY",
        stream="err",
        timeout=BOUND,
    )


def test_topic_info_verbose_shows_the_durations_and_flags_an_incompatible_pair(
    spawn, tmp_path, processes
):
    talker = start(
        spawn, tmp_path, TALKER, "talker", {"reliability": "BEST_EFFORT", "deadline": 2.0}
    )
    start(spawn, tmp_path, LISTENER, "listener", {"reliability": "RELIABLE"})
    talker.expect(r"^offered incompatible", timeout=BOUND)

    info = subprocess.run(
        [sys.executable, "-m", "rosl", "topic", "info", "-v", "/qos_chatter"],
        capture_output=True, text=True, timeout=BOUND, check=False,
    )  # fmt: skip

    assert info.returncode == 0, info.stderr
    assert "  Deadline: 2000000000 nanoseconds" in info.stdout
    assert (
        "Incompatible QoS: no messages to /listener (RELIABILITY: best-effort publisher and "
        "reliable subscription)" in info.stdout
    )
    assert "Incompatible QoS: no messages from /talker (RELIABILITY:" in info.stdout

    doctor = subprocess.run(
        [sys.executable, "-m", "rosl", "doctor"],
        capture_output=True, text=True, timeout=BOUND, check=False,
    )  # fmt: skip
    assert (
        "       UserWarning: Incompatible QoS on /qos_chatter: /listener hears nothing from "
        "/talker (RELIABILITY)." in doctor.stdout
    ), doctor.stdout + doctor.stderr


def test_deadlines_missed_are_told_on_both_sides_once_messages_stop(spawn, tmp_path):
    deadline = {"deadline": 0.5}
    talker = start(spawn, tmp_path, TALKER, "talker", {**deadline, "count": 10})
    listener = start(spawn, tmp_path, LISTENER, "listener", deadline)

    listener.expect(r"^heard on qos_chatter: msg \d+$", timeout=BOUND)
    talker.expect(r"^published 10$", timeout=BOUND)
    talker.expect(r"^offered deadline missed total=\d+ change=\d+$", timeout=BOUND)
    listener.expect(r"^requested deadline missed total=\d+ change=\d+$", timeout=BOUND)
    later = listener.expect(r"^requested deadline missed total=(\d+) change=\d+$", timeout=BOUND)
    assert int(later.group(1)) >= 2  # every period without a message counts again
    assert talker.count(r"^offered incompatible") == 0


def test_lifespan_keeps_stale_latched_messages_from_late_subscribers(spawn, tmp_path):
    latched = {"durability": "TRANSIENT_LOCAL", "count": 3, "period": 0.05}
    short = start(spawn, tmp_path, TALKER, "short",
                  {**latched, "topic": "short_lived", "lifespan": 1.0})  # fmt: skip
    lasting = start(spawn, tmp_path, TALKER, "lasting", {**latched, "topic": "lasting"})
    short.expect(r"^published 3$", timeout=BOUND)
    lasting.expect(r"^published 3$", timeout=BOUND)
    time.sleep(3.0)  # three lifespans: the short-lived messages are stale now

    listener = start(spawn, tmp_path, LISTENER, "late",
                     {"durability": "TRANSIENT_LOCAL", "topics": ["short_lived", "lasting"]})  # fmt: skip
    for n in (1, 2, 3):
        listener.expect(rf"^heard on lasting: msg {n}$", timeout=BOUND)
    time.sleep(1.0)  # any replay of the short-lived ones would have come with the others

    assert listener.count(r"^heard on short_lived") == 0


def test_automatic_liveliness_changes_when_the_publisher_leaves(spawn, tmp_path):
    talker = start(spawn, tmp_path, TALKER, "talker", {})
    listener = start(spawn, tmp_path, LISTENER, "listener", {})
    listener.expect(
        r"^liveliness changed alive=1 not_alive=0 alive_change=1 not_alive_change=0$",
        timeout=BOUND,
    )
    talker.stop()

    listener.expect(
        r"^liveliness changed alive=0 not_alive=0 alive_change=-1 not_alive_change=0$",
        timeout=BOUND,
    )


def test_manual_liveliness_is_lost_when_the_publisher_stops_and_back_when_it_asserts(
    spawn, tmp_path
):
    manual = {"liveliness": "MANUAL_BY_TOPIC", "liveliness_lease_duration": 1.0}
    listener = start(spawn, tmp_path, LISTENER, "listener", manual)
    listener.expect(r"^ready$", timeout=BOUND)
    # it publishes once it sees the listener, for 2 s: two leases for the listener to
    # discover it while its messages still arrive, however slow the machine is
    talker = start(spawn, tmp_path, TALKER, "talker",
                   {**manual, "count": 20, "wait_matched": True, "assert_after_lost": 2.0})  # fmt: skip

    listener.expect(r"^liveliness changed alive=1 not_alive=0 ", timeout=BOUND)
    talker.expect(r"^published 20$", timeout=BOUND)
    talker.expect(r"^liveliness lost total=1 change=1$", timeout=BOUND)
    listener.expect(
        r"^liveliness changed alive=0 not_alive=1 alive_change=-1 not_alive_change=1$",
        timeout=BOUND,
    )
    # assert_liveliness() alone (no messages) makes it alive again
    listener.expect(
        r"^liveliness changed alive=1 not_alive=0 alive_change=1 not_alive_change=-1$",
        timeout=BOUND,
    )
    assert talker.count(r"^published 21") == 0


def test_messages_lost_while_the_subscriber_was_stopped_are_told(spawn, tmp_path):
    trigger = tmp_path / "burst-now"
    burst = {"file": str(trigger), "messages": 3000, "size": 8000}
    talker = start(spawn, tmp_path, TALKER, "talker",
                   {"reliability": "BEST_EFFORT", "burst": burst})  # fmt: skip
    listener = start(spawn, tmp_path, LISTENER, "listener", {"reliability": "BEST_EFFORT"})
    listener.expect(r"^heard on qos_chatter: msg \d+$", timeout=BOUND)

    os.kill(listener.popen.pid, signal.SIGSTOP)  # its socket buffer fills and overflows
    try:
        trigger.write_text("")
        talker.expect(r"^burst done$", timeout=BOUND)
        talker.expect(r"^published \d+$", timeout=BOUND)  # the stream goes on after the gap
    finally:
        os.kill(listener.popen.pid, signal.SIGCONT)

    found = listener.expect(r"^message lost total=(\d+) change=(\d+)$", timeout=BOUND)
    assert int(found.group(1)) > 0
    assert int(found.group(2)) > 0


def test_matched_events_follow_compatible_subscriptions_only(spawn, tmp_path):
    talker = start(spawn, tmp_path, TALKER, "talker", {"reliability": "BEST_EFFORT"})
    talker.expect(r"^ready$", timeout=BOUND)
    first = start(spawn, tmp_path, LISTENER, "first", {"reliability": "BEST_EFFORT"})
    talker.expect(r"^publisher matched total=1 change=1 current=1 current_change=1$", timeout=BOUND)
    start(spawn, tmp_path, LISTENER, "refused", {"reliability": "RELIABLE"})
    talker.expect(r"^offered incompatible total=1 change=1 policy=RELIABILITY$", timeout=BOUND)
    first.stop()

    talker.expect(
        r"^publisher matched total=1 change=0 current=0 current_change=-1$", timeout=BOUND
    )
    assert talker.count(r"current=2") == 0


def test_an_endpoint_of_another_type_is_an_incompatible_type_event(spawn, tmp_path):
    listener = start(spawn, tmp_path, LISTENER, "listener", {})
    listener.expect(r"^ready$", timeout=BOUND)
    spawn(
        "import rosl\n"
        "from std_msgs.msg import Int32\n"
        "rosl.init()\n"
        "node = rosl.Node('other_type')\n"
        "node.create_publisher(Int32, 'qos_chatter', 10)\n"
        "rosl.spin(node)\n"
    )

    listener.expect(r"^incompatible type total=1 change=1$", timeout=BOUND)


def gaps(numbers):
    """The jumps of more than one in a sequence of message numbers."""
    return [b - a for a, b in itertools.pairwise(numbers) if b - a > 1]


def _heard(listener, topic):
    listener.pump()
    return [
        int(n) for n in re.findall(rf"^heard on {topic}: msg (\d+)$", listener.text["out"], re.M)
    ]


def test_messages_past_their_lifespan_when_taken_are_not_delivered(spawn, tmp_path):
    deep = {"depth": 100}
    start(spawn, tmp_path, TALKER, "short", {**deep, "topic": "short_lived", "lifespan": 0.5})
    start(spawn, tmp_path, TALKER, "lasting", {**deep, "topic": "lasting"})
    listener = start(spawn, tmp_path, LISTENER, "listener",
                     {**deep, "topics": ["short_lived", "lasting"]})  # fmt: skip
    listener.expect(r"^heard on short_lived: msg \d+$", timeout=BOUND)
    listener.expect(r"^heard on lasting: msg \d+$", timeout=BOUND)

    os.kill(listener.popen.pid, signal.SIGSTOP)  # messages wait in its socket meanwhile
    try:
        time.sleep(3.0)  # six lifespans
    finally:
        os.kill(listener.popen.pid, signal.SIGCONT)
    before = len(_heard(listener, "short_lived"))
    while len(_heard(listener, "short_lived")) < before + 5:
        listener.expect(r"^heard on short_lived: msg \d+$", timeout=BOUND)

    assert gaps(_heard(listener, "short_lived"))  # the stale ones were dropped
    assert not gaps(_heard(listener, "lasting"))  # the same wait loses nothing without lifespan
    assert listener.count(r"^message lost") == 0


def test_manual_by_node_liveliness_in_one_process_as_the_liveliness_demo_runs(spawn, tmp_path):
    child = spawn(RUN_AS_RCLPY, write(tmp_path, ONE_PROCESS, "one_process"))

    child.expect(r"^changed alive=1 not_alive=0$", timeout=BOUND)  # node.assert_liveliness()
    # the asserting timer was cancelled: both sides are told, in either order
    assert wait_until(lambda: child.count(r"^lost total=1$") == 1, BOUND), child.text
    assert wait_until(lambda: child.count(r"^changed alive=0 not_alive=1$") == 1, BOUND)


def test_a_publisher_that_publishes_serialized_batches_is_told_its_deadline_missed(ros):
    # publish_all (the simulator's paced topics) counts as publishing for the offered deadline
    from rclpy.duration import Duration
    from rclpy.event_handler import PublisherEventCallbacks
    from rclpy.qos import QoSProfile
    from std_msgs.msg import String

    from rosl.idl import registry
    from tests.node.helpers import spin_until

    node = ros.Node("batcher")
    missed = []
    callbacks = PublisherEventCallbacks(deadline=lambda info: missed.append(info.total_count))
    qos = QoSProfile(depth=10, deadline=Duration(seconds=0.2))
    pub = node.create_publisher(String, "batched", qos, event_callbacks=callbacks)
    pub.publish_all([bytes(registry.store().serialize(String(data="one")))])

    assert spin_until(node, lambda: bool(missed), BOUND), "the deadline was never told missed"
    node.destroy_node()
