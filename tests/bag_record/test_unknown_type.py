"""A topic whose type the recorder cannot read: it records the raw bytes with the definition
the publisher's process announces.

The recorder runs in an empty folder; the publisher runs in a workspace whose package defines
``bagtest_msgs/msg/Reading`` (using another message of the package and std_msgs/Header), so
only the publisher can read the .msg files.
"""

from __future__ import annotations

import signal
from typing import TYPE_CHECKING

import pytest

from rosl.idl import registry
from tests.bag_record import support

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.conftest import Processes

READING = """\
# A custom reading only the publisher's workspace knows.
std_msgs/Header header
Sample[] samples   # several samples
string note
int32 LIMIT=5
"""
SAMPLE = "float64 value\nuint8 quality\n"
TYPE = "bagtest_msgs/msg/Reading"
MESSAGES = [
    {
        "header": {"stamp": {"sec": 10 + i, "nanosec": 5}, "frame_id": "lab"},
        "samples": [{"value": 0.25 * k, "quality": k} for k in range(i)],
        "note": f"reading {i}",
    }
    for i in range(4)
]


def test_a_type_unknown_to_the_recorder_is_recorded_with_the_publishers_definition(
    processes: Processes, make_package: Callable[..., Path], workspace: Path, tmp_path: Path
) -> None:
    make_package("bagtest_msgs", {"msg/Reading.msg": READING, "msg/Sample.msg": SAMPLE})
    expected_text = registry.msgdef_text(TYPE)
    expected_bytes = [support.cdr(TYPE, m) for m in MESSAGES]
    empty = tmp_path / "recorder_cwd"
    empty.mkdir()
    folder = tmp_path / "custom_bag"
    recorder = support.start_recorder(
        processes, "-a", "-o", str(folder), "--distro", "jazzy", cwd=empty
    )  # Jazzy's layout: metadata.yaml holds type hashes
    # the publisher does not wait for the recorder: its messages come while the recorder is
    # still asking for the type, and must be kept until the definition arrives; it stays up
    # long enough (the recorder's 3 s bound) to answer however loaded the machine is
    support.run_publisher(
        processes,
        {"node": "custom_talker", "publishers": [{"topic": "/reading", "type": TYPE, "wait": 0}],
         "messages": [(0, m) for m in MESSAGES], "settle": 0.5, "period": 0.05, "linger": 3.0},
        cwd=workspace,
    )  # fmt: skip
    support.stop_recorder(recorder, signal.SIGINT)

    assert support.topic_counts(folder)["/reading"] == len(MESSAGES)
    (mcap_file,) = support.read_mcap(folder)
    assert mcap_file.schemas[TYPE] == ("ros2msg", expected_text)
    found = support.by_topic(mcap_file.messages)["/reading"]
    assert [m.data for m in found] == expected_bytes
    meta = {
        e["topic_metadata"]["name"]: e["topic_metadata"]
        for e in support.metadata(folder)["topics_with_message_count"]
    }
    assert meta["/reading"]["type"] == TYPE
    assert meta["/reading"]["type_description_hash"] == support.rihs01(
        TYPE, "ros2msg", expected_text
    )
    decoded = support.by_topic(support.read_anyreader(folder))["/reading"]
    assert [m.fields for m in decoded] == [
        support.plain(support.sent_message(TYPE, m)) for m in MESSAGES
    ]


@pytest.mark.slow
def test_a_publisher_of_a_type_the_recorder_asked_for_sees_the_recorder_matched(
    processes: Processes, make_package: Callable[..., Path], workspace: Path, tmp_path: Path
) -> None:
    """Once the definition has arrived, the recorder subscribes and says so in the graph.

    A first node makes the recorder subscribe to /rosout and /parameter_events, so that when
    the custom publisher appears nothing else changes in the graph after the recorder has
    asked for the type. A publisher waiting for a matched subscription (as ``topic pub
    --once`` does) must still see the recorder.
    """
    make_package("bagtest_msgs", {"msg/Reading.msg": READING, "msg/Sample.msg": SAMPLE})
    empty = tmp_path / "recorder_cwd"
    empty.mkdir()
    folder = tmp_path / "custom_bag"
    recorder = support.start_recorder(
        processes, "-a", "-o", str(folder), "--distro", "jazzy", cwd=empty
    )  # Jazzy's layout: metadata.yaml holds type hashes
    support.run_publisher(
        processes,
        {"node": "warmup", "publishers": [{"topic": "/warmup", "type": "std_msgs/msg/Int32"}],
         "messages": [(0, {"data": 1})], "linger": 0.0},
        cwd=empty,
    )  # fmt: skip
    waiting = support.start_publisher(
        processes,
        {"node": "custom_talker", "publishers": [{"topic": "/reading", "type": TYPE, "wait": 1}],
         "messages": [(0, m) for m in MESSAGES], "wait_timeout": 30.0},
        cwd=workspace,
    )  # fmt: skip
    code = waiting.finish(60)
    support.stop_recorder(recorder, signal.SIGINT)
    assert code == 0, f"the recorder never matched /reading\n{waiting.both()}"
    assert support.topic_counts(folder)["/reading"] == len(MESSAGES)


def test_reindex_hashes_a_type_it_does_not_know_from_the_schema_in_the_file(
    processes: Processes, make_package: Callable[..., Path], workspace: Path, tmp_path: Path
) -> None:
    """metadata.yaml rebuilt by a process that cannot read bagtest_msgs still carries the
    type's RIHS01 hash: reindex computes it from the definition the MCAP file holds."""
    make_package("bagtest_msgs", {"msg/Reading.msg": READING, "msg/Sample.msg": SAMPLE})
    expected_text = registry.msgdef_text(TYPE)
    empty = tmp_path / "recorder_cwd"
    empty.mkdir()
    folder = tmp_path / "custom_bag"
    recorder = support.start_recorder(
        processes, "/reading", "-o", str(folder), "--distro", "jazzy", cwd=empty
    )
    support.run_publisher(
        processes,
        {"node": "custom_talker", "publishers": [{"topic": "/reading", "type": TYPE}],
         "messages": [(0, m) for m in MESSAGES]},
        cwd=workspace,
    )  # fmt: skip
    support.stop_recorder(recorder, signal.SIGINT)
    (folder / "metadata.yaml").unlink()

    result = support.rosl_run("bag", "reindex", str(folder), cwd=empty)
    assert result.returncode == 0, result.stderr
    (entry,) = support.metadata(folder)["topics_with_message_count"]
    assert entry["topic_metadata"]["type"] == TYPE
    assert entry["message_count"] == len(MESSAGES)
    assert entry["topic_metadata"]["type_description_hash"] == support.rihs01(
        TYPE, "ros2msg", expected_text
    )
    assert entry["topic_metadata"]["type_description_hash"].startswith("RIHS01_")
