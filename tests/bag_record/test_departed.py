"""A process that announces itself, publishes and leaves while the recorder is busy is recorded.

The recorder names a message by the graph; discovery runs on its own thread, so it can hear a
process arrive and say goodbye before the recording thread reaches that process's messages
(a recorder busy for a moment: a first import, a slow disk). The test makes that happen every
time: the recorder is stopped (SIGSTOP) while a talker announces, publishes and exits, then
continued. Every message must be in the bag, named and typed.
"""

from __future__ import annotations

import signal
from typing import TYPE_CHECKING

from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

COUNT = 20


def test_messages_of_a_process_that_left_before_they_were_read_are_recorded(
    processes: Processes, tmp_path: Path
) -> None:
    folder = tmp_path / "departed"
    recorder = support.start_recorder(processes, "-a", "-o", str(folder), cwd=tmp_path)
    recorder.popen.send_signal(signal.SIGSTOP)
    try:
        support.run_publisher(
            processes,
            {"node": "passing_talker", "wait_subscribers": 0,
             "publishers": [{"topic": "/departed", "type": "std_msgs/msg/String"}],
             "messages": [(0, {"data": f"message {i}"}) for i in range(COUNT)]},
            cwd=tmp_path,
        )  # fmt: skip
    finally:
        recorder.popen.send_signal(signal.SIGCONT)
    assert recorder.wait_for("Subscribed to topic '/departed'", stream="err", timeout=30), (
        recorder.both()
    )
    support.stop_recorder(recorder)

    read = support.by_topic(support.read_anyreader(folder)).get("/departed", [])
    assert [m.fields for m in read] == [{"data": f"message {i}"} for i in range(COUNT)]
