"""Splitting (``--max-bag-duration``, ``--max-bag-size``) and ``--compression-format``.

Four recorders run at once on one domain while one publisher sends, over about 4 s, a
counter (Int32 1..200) interleaved with 2 kB strings: one splits every second, one every
30 kB, one compresses chunks with zstd and one with lz4. Every bag is read back with the
three readers and compared with the bytes and values that were sent.
"""

from __future__ import annotations

import signal
from dataclasses import dataclass
from typing import TYPE_CHECKING

import pytest

from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path

    from tests.bag_record.conftest import DomainProcesses

pytestmark = pytest.mark.slow

COUNT = 200
SIZE_LIMIT = 30_000
PUBLISHERS = [
    {"topic": "/counter", "type": "std_msgs/msg/Int32", "wait": 4},
    {"topic": "/blob", "type": "std_msgs/msg/String", "wait": 4},
]
MESSAGES = [
    m
    for i in range(1, COUNT + 1)
    for m in ((0, {"data": i}), (1, {"data": f"{i:04d}" + "x" * 2000}))
]
EXPECTED = {
    "/counter": [support.cdr("std_msgs/msg/Int32", f) for w, f in MESSAGES if w == 0],
    "/blob": [support.cdr("std_msgs/msg/String", f) for w, f in MESSAGES if w == 1],
}


@dataclass
class Bags:
    duration: Path
    size: Path
    zstd: Path
    lz4: Path


@pytest.fixture(scope="module")
def bags(module_bus: DomainProcesses, module_dir: Path) -> Bags:
    found = Bags(*(module_dir / name for name in ("by_duration", "by_size", "zstd", "lz4")))
    recorders = [
        support.start_recorder(module_bus, "-a", "--max-bag-duration", "1", "-o",
                               str(found.duration), cwd=module_dir),
        support.start_recorder(module_bus, "-a", "--max-bag-size", str(SIZE_LIMIT), "-o",
                               str(found.size), cwd=module_dir),
        support.start_recorder(module_bus, "-a", "--compression-format", "zstd", "-o",
                               str(found.zstd), cwd=module_dir),
        support.start_recorder(module_bus, "-a", "--compression-format", "lz4", "-o",
                               str(found.lz4), cwd=module_dir),
    ]  # fmt: skip
    support.run_publisher(
        module_bus,
        {"node": "split_talker", "publishers": PUBLISHERS, "messages": MESSAGES,
         "period": 4.0 / len(MESSAGES)},
        cwd=module_dir,
    )  # fmt: skip
    for recorder in recorders:
        support.stop_recorder(recorder, signal.SIGINT)
    return found


def check_every_reader(folder: Path) -> None:
    """All three readers read every message, in order, with the exact bytes sent."""
    mcap = support.by_topic([m for f in support.read_mcap(folder) for m in f.messages])
    anyreader = support.by_topic(support.read_anyreader(folder))
    rosbag2 = support.by_topic(support.read_rosbag2(folder))
    for topic, expected in EXPECTED.items():
        assert [m.data for m in mcap[topic]] == expected, topic
        assert [m.data for m in anyreader[topic]] == expected, topic
        assert [m.data for m in rosbag2[topic]] == expected, topic
    values = list(range(1, COUNT + 1))
    assert [m.fields["data"] for m in anyreader["/counter"]] == values
    assert [m.fields["data"] for m in rosbag2["/counter"]] == values
    assert [m.fields["data"] for m in mcap["/counter"]] == values


def check_split(folder: Path) -> list[Path]:
    """Several files, all listed in metadata.yaml, each finished and counted right."""
    info = support.metadata(folder)
    files = support.bag_files(folder)
    assert len(files) >= 2, info["relative_file_paths"]
    assert sorted(p.name for p in folder.glob("*.mcap")) == sorted(p.name for p in files)
    for entry, path in zip(info["files"], files, strict=True):
        content = support.read_mcap_file(path)
        assert entry["path"] == path.name
        assert entry["message_count"] == len(content.messages) == content.statistics.message_count
    # in metadata order, the files follow each other in time
    ends = [max(m.log_time for m in support.read_mcap_file(p).messages) for p in files if
            support.read_mcap_file(p).messages]  # fmt: skip
    starts = [min(m.log_time for m in support.read_mcap_file(p).messages) for p in files if
              support.read_mcap_file(p).messages]  # fmt: skip
    assert all(end <= start for end, start in zip(ends, starts[1:], strict=False))
    # per-channel sequence numbers go on across files
    sequences = [m.sequence for p in files for m in support.read_mcap_file(p).messages
                 if m.topic == "/counter"]  # fmt: skip
    assert sequences == list(range(1, COUNT + 1))
    return files


def test_max_bag_duration_splits_the_recording_into_several_files(bags: Bags) -> None:
    check_split(bags.duration)


def test_no_file_split_by_duration_holds_much_more_than_the_duration(bags: Bags) -> None:
    """With --max-bag-duration 1, a file's messages span about a second, not two.

    rosbag2 starts a new file as soon as the current one is max-bag-duration old; checking
    once a second (at each flush) may add up to that second's granularity, so 1.5 s is the
    bound here.
    """
    spans = {}
    for path in support.bag_files(bags.duration):
        stamps = [m.log_time for m in support.read_mcap_file(path).messages]
        spans[path.name] = (max(stamps) - min(stamps)) / 1e9 if stamps else 0.0
    assert max(spans.values()) < 1.5, spans


def test_a_bag_split_by_duration_reads_whole_and_in_order(bags: Bags) -> None:
    check_every_reader(bags.duration)


def test_max_bag_size_starts_a_new_file_once_one_reaches_the_size(bags: Bags) -> None:
    files = check_split(bags.size)
    assert all(p.stat().st_size >= SIZE_LIMIT for p in files[:-1]), [
        p.stat().st_size for p in files
    ]


def test_a_bag_split_by_size_reads_whole_and_in_order(bags: Bags) -> None:
    check_every_reader(bags.size)


@pytest.mark.parametrize("compression", ["zstd", "lz4"])
def test_compressed_chunks_are_read_by_every_reader_with_identical_bytes(
    bags: Bags, compression: str
) -> None:
    from mcap.reader import make_reader

    folder = getattr(bags, compression)
    for path in support.bag_files(folder):
        with path.open("rb") as handle:
            summary = make_reader(handle).get_summary()
        assert summary is not None
        assert summary.chunk_indexes
        assert {c.compression for c in summary.chunk_indexes} == {compression}
        # compression did shrink the repetitive strings
        assert sum(c.compressed_size for c in summary.chunk_indexes) < sum(
            c.uncompressed_size for c in summary.chunk_indexes
        )
    check_every_reader(folder)
    assert support.topic_counts(folder)["/counter"] == COUNT
