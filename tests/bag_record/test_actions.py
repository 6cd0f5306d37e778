"""Action topics in recordings, as rosbag2 (Humble, Jazzy) records them.

``<action>/_action/feedback`` and ``<action>/_action/status`` are hidden names: ``-a`` leaves
them out (rosbag2's topic filter: "Hidden topics are not recorded") and
``--include-hidden-topics`` records them. The bag then reads back in rosbags with the goal's
feedback and every status array, with ROS 2's type hash on the feedback channel.
"""

from __future__ import annotations

import signal
import sys
from typing import TYPE_CHECKING

from rosl.graph.records import PUBLISHER, SUBSCRIPTION
from tests.bag_record import support
from tests.cli.conftest import run, wait_graph
from tests.node.action_programs import RUN_AS_RCLPY, SERVER, write

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

FEEDBACK = "/fibonacci/_action/feedback"
STATUS = "/fibonacci/_action/status"
FEEDBACK_HASH = "RIHS01_c1de71afd52e49a89c53d8262366884185bc0a02f78ce051c4e46b0a7fe59bb2"


def _record_one_goal(processes: Processes, folder: Path, *selection: str) -> None:
    recorder = support.start_recorder(processes, *selection, "-o", str(folder))
    if "--include-hidden-topics" in selection:
        wait_graph(lambda g: g.count(SUBSCRIPTION, STATUS) >= 1)
    result = run(
        processes, "action", "send_goal", "/fibonacci", "example_interfaces/action/Fibonacci",
        "{order: 4}", timeout=60,
    )  # fmt: skip
    assert result.code == 0, result
    support.stop_recorder(recorder, signal.SIGINT)


def test_action_topics_are_recorded_with_include_hidden_topics_and_read_back(
    processes: Processes, tmp_path: Path
) -> None:
    server = write(tmp_path, "fibonacci_server.py", SERVER)
    processes.start([sys.executable, "-c", RUN_AS_RCLPY, server, "--delay", "0.02"])
    wait_graph(lambda g: g.count(PUBLISHER, FEEDBACK) == 1)

    _record_one_goal(processes, tmp_path / "plain", "-a")
    _record_one_goal(processes, tmp_path / "hidden", "-a", "--include-hidden-topics")

    assert not {FEEDBACK, STATUS} & set(support.topic_counts(tmp_path / "plain"))
    messages = support.by_topic(support.read_anyreader(tmp_path / "hidden"))
    feedback = [m.fields["feedback"]["sequence"] for m in messages[FEEDBACK]]
    assert feedback == [[0, 1, 1], [0, 1, 1, 2], [0, 1, 1, 2, 3]]
    assert messages[FEEDBACK][0].type == "example_interfaces/action/Fibonacci_FeedbackMessage"
    last = messages[STATUS][-1].fields["status_list"]
    assert [s["status"] for s in last][-1] == 4  # SUCCEEDED
    assert support.channel_hashes(tmp_path / "hidden")[FEEDBACK] == FEEDBACK_HASH
