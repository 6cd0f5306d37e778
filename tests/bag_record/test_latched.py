"""A recorder started late gets what a late transient-local subscriber gets.

The test process publishes on a transient-local topic (depth 3) and a volatile one before any
recorder runs; then ``rosl bag record -a`` starts. As rosbag2 does, the recorder subscribes
transient local where every publisher offers it, so the kept history arrives and is recorded
once, also when a message comes both live and in the history. The volatile topic's earlier
messages are gone, but the topic is in the bag: its channel and its metadata entry, count 0.
"""

from __future__ import annotations

import signal
from typing import TYPE_CHECKING

from rosl.bag.selection import RECORDER_NODE
from rosl.graph.records import SUBSCRIPTION
from tests.bag_record import support
from tests.conftest import wait_until

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes


def test_a_late_recorder_records_the_latched_history_once_and_lists_the_silent_topic(
    ros: object, processes: Processes, tmp_path: Path
) -> None:
    from std_msgs.msg import String

    from rosl.node.qos import DurabilityPolicy, QoSProfile

    node = ros.Node("latcher")  # type: ignore[attr-defined]
    latched = node.create_publisher(
        String, "/static", QoSProfile(depth=3, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    )
    plain = node.create_publisher(String, "/plain", 10)
    for index in range(5):
        latched.publish(String(data=f"static {index}"))
    plain.publish(String(data="gone before anyone listened"))
    graph = node.participant.graph

    def recorder_stat(topic: str, key: str) -> int:
        found = [e for n, e in graph.endpoints(SUBSCRIPTION, topic) if n.name == RECORDER_NODE]
        return int(found[0].stats.get(key, -1)) if found else -1

    folder = tmp_path / "late"
    recorder = support.start_recorder(processes, "-a", "-o", str(folder))
    assert wait_until(lambda: recorder_stat("/static", "received") == 3, timeout=30.0), (
        graph.endpoints(SUBSCRIPTION, "/static")
    )
    ((owner, subscription),) = graph.endpoints(SUBSCRIPTION, "/static")
    assert subscription.qos["durability"] == "TRANSIENT_LOCAL"
    latched.publish(String(data="static 5"))  # live, and in the history from now on
    assert wait_until(lambda: recorder_stat("/static", "received") == 4, timeout=30.0)
    # the history again (as when a request crosses live messages): all recorded already
    latched.replay((owner.process, subscription.endpoint))
    latched.publish(String(data="static 6"))  # sent after the replayed copies
    assert wait_until(lambda: recorder_stat("/static", "received") == 5, timeout=30.0)
    support.stop_recorder(recorder, signal.SIGINT)

    found = support.by_topic(support.read_anyreader(folder))
    assert [m.fields["data"] for m in found["/static"]] == [f"static {i}" for i in range(2, 7)]
    assert "/plain" not in found
    counts = support.topic_counts(folder)
    assert (counts["/static"], counts["/plain"]) == (5, 0)
    channels = {t for f in support.read_mcap(folder) for t in f.channels}
    assert channels == set(counts)  # every listed topic has its channel, with messages or not
