"""The recorder asks the reliability its publishers offer, as rosbag2 does.

A best-effort publisher (a sensor) is recorded by a best-effort subscription, so the publisher
sees no incompatible-QoS subscription and logs no warning; a reliable publisher is recorded by
a reliable one.
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


def test_the_recorder_subscribes_best_effort_to_a_best_effort_publisher(
    ros: object, processes: Processes, tmp_path: Path
) -> None:
    from std_msgs.msg import String

    from rosl.node.qos import QoSProfile, ReliabilityPolicy

    node = ros.Node("sensor")  # type: ignore[attr-defined]
    incompatible: list[object] = []
    from rosl.compat.rclpy.qos_event import PublisherEventCallbacks

    node.create_publisher(
        String, "/sensed", QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT),
        event_callbacks=PublisherEventCallbacks(incompatible_qos=incompatible.append),
    )  # fmt: skip
    node.create_publisher(String, "/commanded", 10)
    graph = node.participant.graph

    def recorder_qos(topic: str) -> dict[str, object] | None:
        found = [e for n, e in graph.endpoints(SUBSCRIPTION, topic) if n.name == RECORDER_NODE]
        return found[0].qos if found else None

    recorder = support.start_recorder(processes, "-a", "-o", str(tmp_path / "bag"))
    try:
        assert wait_until(
            lambda: recorder_qos("/sensed") is not None and recorder_qos("/commanded") is not None,
            timeout=30.0,
        ), graph.endpoints(SUBSCRIPTION)
        assert recorder_qos("/sensed")["reliability"] == "BEST_EFFORT"  # type: ignore[index]
        assert recorder_qos("/commanded")["reliability"] == "RELIABLE"  # type: ignore[index]
        ros.spin_once(node, timeout_sec=0.5)  # type: ignore[attr-defined]
        assert incompatible == []
    finally:
        support.stop_recorder(recorder, signal.SIGINT)
