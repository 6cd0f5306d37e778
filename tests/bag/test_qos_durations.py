"""A recorded topic's offered QoS keeps its deadline, lifespan and lease, as rosbag2 writes them."""

from __future__ import annotations

from rosl.bag.metadata import qos_entry
from rosl.node.clock import Duration
from rosl.node.qos import QoSProfile


def test_offered_qos_holds_set_durations_and_infinite_for_the_rest():
    words = QoSProfile(
        depth=3, deadline=Duration(seconds=1.5), liveliness_lease_duration=Duration(seconds=2)
    ).words()

    entry = qos_entry(words)

    assert entry["deadline"] == {"sec": 1, "nsec": 500_000_000}
    assert entry["liveliness_lease_duration"] == {"sec": 2, "nsec": 0}
    assert entry["lifespan"] == {"sec": 9223372036854775807, "nsec": 4294967295}
    assert entry["depth"] == 3
