"""``rosl bag reindex`` on odd folders: files that are not MCAP, many split files without a
metadata.yaml, a disk that refuses the rewrite, compressed recordings, topics with no messages.

Two recorders run at once while one publisher sends a counter (Int32 1..50 at 20 Hz) on
/counter and nothing on /silent: one records both topics with zstd chunks into one file
(several chunks, since chunks go out every second), the other records /counter with lz4 and
``--max-bag-size 1``, so every message gets a file of its own (``split_0`` .. ``split_49``).
Each test alters a copy of those folders.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING

import pytest

from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path

    from tests.bag_record.conftest import DomainProcesses

pytestmark = pytest.mark.slow

COUNT = 50
COUNTER = [support.cdr("std_msgs/msg/Int32", {"data": v}) for v in range(1, COUNT + 1)]


@dataclass
class Recorded:
    zstd: Path
    split: Path


@pytest.fixture(scope="module")
def recorded(module_bus: DomainProcesses, module_dir: Path) -> Recorded:
    found = Recorded(module_dir / "zstd", module_dir / "split")
    recorders = [
        support.start_recorder(module_bus, "/counter", "/silent", "--compression-format", "zstd",
                               "-o", str(found.zstd), cwd=module_dir),
        support.start_recorder(module_bus, "/counter", "--compression-format", "lz4",
                               "--max-bag-size", "1", "-o", str(found.split), cwd=module_dir),
    ]  # fmt: skip
    support.run_publisher(
        module_bus,
        {"node": "reindex_talker", "period": 0.05,
         "publishers": [{"topic": "/counter", "type": "std_msgs/msg/Int32", "wait": 2},
                        {"topic": "/silent", "type": "std_msgs/msg/String", "wait": 1}],
         "messages": [(0, {"data": v}) for v in range(1, COUNT + 1)]},
        cwd=module_dir,
    )  # fmt: skip
    for recorder in recorders:
        support.stop_recorder(recorder, signal.SIGINT)
    assert support.topic_counts(found.zstd) == {"/counter": COUNT, "/silent": 0}
    assert len(list(found.split.glob("*.mcap"))) == COUNT
    return found


def copy_of(folder: Path, tmp_path: Path) -> Path:
    copy = tmp_path / folder.name
    shutil.copytree(folder, copy)
    return copy


def snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def one_line_error(result: subprocess.CompletedProcess[str]) -> str:
    assert result.returncode == 1, (result.returncode, result.stdout, result.stderr)
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    return lines[0]


def cut_in_half(path: Path) -> int:
    """Truncate ``path`` in the middle of its data; how many of its messages stay whole."""
    from mcap.reader import make_reader

    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None
    cut = path.stat().st_size // 2
    whole = [c for c in summary.chunk_indexes if c.chunk_start_offset + c.chunk_length <= cut]
    assert whole, "the cut leaves no complete chunk; the recording is too small"
    with path.open("r+b") as handle:
        handle.truncate(cut)
    return len(support.complete_messages(path))


# --- a file that is not MCAP -------------------------------------------------------------------


def test_reindex_refuses_a_file_that_is_not_mcap_and_changes_nothing(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.zstd, tmp_path)
    (real,) = folder.glob("*.mcap")
    cut_in_half(real)  # an unfinished file reindex would otherwise rewrite
    (folder / "zstd_1.mcap").write_text("notes, not a recording\n")
    before = snapshot(folder)
    line = one_line_error(support.rosl_run("bag", "reindex", str(folder)))
    assert "zstd_1.mcap" in line
    assert "not an MCAP file" in line
    assert snapshot(folder) == before


def test_reindex_of_a_folder_holding_only_a_non_mcap_file_leaves_it_whole(tmp_path: Path) -> None:
    folder = tmp_path / "bag"
    folder.mkdir()
    fake = folder / "bag_0.mcap"
    fake.write_bytes(b"PK\x03\x04 a zip file named like a recording" * 10)
    before = snapshot(folder)
    line = one_line_error(support.rosl_run("bag", "reindex", str(folder)))
    assert "bag_0.mcap" in line
    assert "not an MCAP file" in line
    assert snapshot(folder) == before


# --- split files without metadata.yaml ---------------------------------------------------------


def test_split_files_without_metadata_are_read_and_reindexed_in_numeric_order(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.split, tmp_path)
    (folder / "metadata.yaml").unlink()
    in_order = [f"split_{i}.mcap" for i in range(COUNT)]

    info = support.rosl_run("bag", "info", "--json", str(folder))
    assert info.returncode == 0, info.stderr
    assert json.loads(info.stdout)["files"] == in_order

    result = support.rosl_run("bag", "reindex", str(folder))
    assert result.returncode == 0, result.stderr
    meta = support.metadata(folder)
    assert meta["relative_file_paths"] == in_order
    assert [f["path"] for f in meta["files"]] == in_order
    starts = [f["starting_time"]["nanoseconds_since_epoch"] for f in meta["files"]]
    assert starts == sorted(starts)
    # each file holds one message: in file order they are the counter 1..50
    values = [m.fields["data"] for path in support.bag_files(folder)
              for m in support.read_mcap_file(path).messages]  # fmt: skip
    assert values == list(range(1, COUNT + 1))
    assert [m.data for m in support.read_rosbag2(folder)] == COUNTER


# --- a disk that refuses the rewrite -----------------------------------------------------------

# reindex in a process whose files may not grow past a limit: writes fail as on a full disk
LIMITED = r"""
import os, resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
os.execv(sys.executable, [sys.executable, "-m", "rosl", *sys.argv[2:]])
"""


def test_reindex_on_a_full_disk_says_so_in_one_line_and_leaves_the_original(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.zstd, tmp_path)
    (path,) = folder.glob("*.mcap")
    cut_in_half(path)
    before = snapshot(folder)
    limit = 256  # well below what the rewritten file needs
    assert path.stat().st_size > limit
    result = subprocess.run(
        [sys.executable, "-c", LIMITED, str(limit), "bag", "reindex", str(folder)],
        capture_output=True, text=True, timeout=60, check=False,
        env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"},
    )  # fmt: skip
    line = one_line_error(result)
    assert path.name in line
    assert snapshot(folder) == before  # no *.mcap.reindex left behind, the original untouched
    # with room on the disk, the same folder is repaired
    repaired = support.rosl_run("bag", "reindex", str(folder))
    assert repaired.returncode == 0, repaired.stderr
    assert sorted(p.name for p in folder.iterdir()) == ["metadata.yaml", path.name]
    assert path.stat().st_size > limit


# --- what a rewrite and a rebuilt metadata.yaml keep -------------------------------------------


def test_reindex_keeps_the_chunk_compression_of_the_recording(
    recorded: Recorded, tmp_path: Path
) -> None:
    from mcap.reader import make_reader

    folder = copy_of(recorded.zstd, tmp_path)
    (path,) = folder.glob("*.mcap")
    whole = cut_in_half(path)
    result = support.rosl_run("bag", "reindex", str(folder))
    assert result.returncode == 0, result.stderr
    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None
    assert summary.chunk_indexes
    assert {c.compression for c in summary.chunk_indexes} == {"zstd"}
    assert [m.data for m in support.read_anyreader(folder)] == COUNTER[:whole]


def test_reindex_keeps_the_topics_metadata_listed_without_messages(
    recorded: Recorded, tmp_path: Path
) -> None:
    folder = copy_of(recorded.zstd, tmp_path)
    old = {
        e["topic_metadata"]["name"]: e
        for e in support.metadata(folder)["topics_with_message_count"]
    }
    (path,) = folder.glob("*.mcap")
    whole = cut_in_half(path)
    result = support.rosl_run("bag", "reindex", str(folder))
    assert result.returncode == 0, result.stderr
    new = {
        e["topic_metadata"]["name"]: e
        for e in support.metadata(folder)["topics_with_message_count"]
    }
    assert new["/silent"] == old["/silent"]  # type, QoS, hash, and Count: 0
    assert new["/silent"]["message_count"] == 0
    assert new["/counter"]["message_count"] == whole
    # rosbags reads the rebuilt folder (a topic with no channel is allowed)
    assert len(support.read_rosbag2(folder)) == whole
