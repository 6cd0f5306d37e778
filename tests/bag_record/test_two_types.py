"""One topic published with two types: the recorder keeps the first type seen, as rosbag2 does.

A String publisher on /mixed is recorded first; then an Int32 publisher on /mixed sends four
messages. Those are counted and reported (one warning naming the topic, both types and the
publishing node; their count in the stop summary), never written under String's schema: every
reader decodes the bag and finds only the strings.
"""

from __future__ import annotations

import re
import signal
from typing import TYPE_CHECKING

from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

STRINGS = ["first", "second", "third"]
NUMBERS = [7, 8, 9, 10]


def test_a_second_type_on_a_recorded_topic_is_counted_and_never_written(
    processes: Processes, tmp_path: Path
) -> None:
    folder = tmp_path / "mixed"
    recorder = support.start_recorder(processes, "-a", "-o", str(folder), cwd=tmp_path)
    support.run_publisher(
        processes,
        {"node": "string_talker", "linger": 0.3,
         "publishers": [{"topic": "/mixed", "type": "std_msgs/msg/String"}],
         "messages": [(0, {"data": text}) for text in STRINGS]},
        cwd=tmp_path,
    )  # fmt: skip
    support.run_publisher(
        processes,
        {"node": "int_talker", "settle": 0.5,
         "publishers": [{"topic": "/mixed", "type": "std_msgs/msg/Int32"}],
         "messages": [(0, {"data": n}) for n in NUMBERS]},
        cwd=tmp_path,
    )  # fmt: skip
    err = support.stop_recorder(recorder, signal.SIGINT)

    warnings = [line for line in err.splitlines() if "/mixed" in line and "[WARN]" in line]
    assert len(warnings) == 1, err
    for word in ("std_msgs/msg/String", "std_msgs/msg/Int32", "/int_talker"):
        assert word in warnings[0], warnings[0]
    stopped = [line for line in err.splitlines() if "Recording stopped" in line]
    assert len(stopped) == 1, err
    assert re.search(rf"\b{len(NUMBERS)} on /mixed as std_msgs/msg/Int32\b", stopped[0]), stopped

    meta = {
        e["topic_metadata"]["name"]: e
        for e in support.metadata(folder)["topics_with_message_count"]
    }
    assert meta["/mixed"]["topic_metadata"]["type"] == "std_msgs/msg/String"
    assert meta["/mixed"]["message_count"] == len(STRINGS)
    expected = [support.cdr("std_msgs/msg/String", {"data": text}) for text in STRINGS]
    for read in (support.read_anyreader, support.read_rosbag2):
        mixed = support.by_topic(read(folder))["/mixed"]
        assert [m.data for m in mixed] == expected
        assert [m.fields["data"] for m in mixed] == STRINGS
    (mcap_file,) = support.read_mcap(folder)
    mixed = support.by_topic(mcap_file.messages)["/mixed"]
    assert [(m.type, m.fields["data"]) for m in mixed] == [
        ("std_msgs/msg/String", t) for t in STRINGS
    ]
    assert [m.sequence for m in mixed] == [1, 2, 3]
