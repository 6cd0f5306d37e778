"""Bad inputs: where a recording cannot go, and damaged or odd bags given to info/reindex.

The damaged bags are copies of one real recording (a counter 1..50 at 20 Hz, so its file
holds several chunks), altered in the test: metadata.yaml removed, metadata.yaml naming a
file that is not there, the .mcap cut in half, a file that is not MCAP at all.
"""

from __future__ import annotations

import os
import shutil
import signal
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
import yaml

from tests.bag_record import support

if TYPE_CHECKING:
    from subprocess import CompletedProcess

    from tests.bag_record.conftest import DomainProcesses
    from tests.conftest import Processes

COUNT = 50


def snapshot(folder: Path) -> dict[str, tuple[bytes, int]]:
    return {
        str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else b"", p.stat().st_mtime_ns)
        for p in sorted(folder.rglob("*"))
    }


# --- where a recording cannot go ---------------------------------------------------------------


def record_once(tmp_path: Path, target: Path) -> CompletedProcess[str]:
    """Run the recorder expecting it to refuse at once (bounded)."""
    return support.rosl_run("bag", "record", "-a", "-o", str(target), cwd=tmp_path, timeout=30)


def test_recording_into_a_non_empty_folder_fails_and_leaves_it_untouched(
    tmp_path: Path, domain_id: int
) -> None:
    folder = tmp_path / "old_run"
    folder.mkdir()
    (folder / "notes.txt").write_text("keep me\n")
    (folder / "old_run_0.mcap").write_bytes(b"\x89MCAP0\r\nprecious")
    before = snapshot(folder)
    result = record_once(tmp_path, folder)
    line = support.one_line_error(result)
    assert str(folder) in line
    assert "Recording" not in result.stderr
    assert snapshot(folder) == before


def test_recording_under_a_path_that_is_a_file_fails_with_one_line(
    tmp_path: Path, domain_id: int
) -> None:
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("a file\n")
    result = record_once(tmp_path, blocker / "run")
    line = support.one_line_error(result)
    assert "not_a_folder" in line
    assert "Recording to" not in result.stderr
    assert "Recording stopped" not in result.stderr
    assert blocker.read_text() == "a file\n"


def test_recording_into_a_read_only_folder_fails_with_one_line(
    tmp_path: Path, domain_id: int
) -> None:
    parent = tmp_path / "read_only"
    parent.mkdir()
    parent.chmod(0o500)
    try:
        # root writes into a 0o500 folder; /sys refuses anyone a new folder
        target = Path("/sys/rosl_test_run") if os.access(parent, os.W_OK) else parent / "run"
        result = record_once(tmp_path, target)
        line = support.one_line_error(result)
        assert line.startswith(f"cannot record into '{target}': ")
        assert "Recording to" not in result.stderr
        assert list(parent.iterdir()) == []
        assert not target.exists()
    finally:
        parent.chmod(0o700)


@pytest.mark.parametrize(
    ("args", "start"),
    [
        (["--exclude", "(["], "--exclude: not a valid regular expression"),
        (["--max-bag-size", "-5"], "--max-bag-size must be 0"),
        (["--max-bag-duration", "-1.5"], "--max-bag-duration must be 0"),
    ],
)
def test_bad_record_options_are_refused_in_one_line_before_recording(
    tmp_path: Path, domain_id: int, args: list[str], start: str
) -> None:
    folder = tmp_path / "run"
    result = support.rosl_run("bag", "record", "-a", *args, "-o", str(folder), cwd=tmp_path)
    line = support.one_line_error(result)
    assert line.startswith(start), line
    assert "Recording" not in result.stderr
    assert not folder.exists()


# --- damaged bags ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def good_bag(module_bus: DomainProcesses, module_dir: Path) -> Path:
    folder = module_dir / "good"
    recorder = support.start_recorder(module_bus, "-a", "-o", str(folder), cwd=module_dir)
    support.run_publisher(
        module_bus,
        {"node": "bad_input_talker", "publishers": [{"topic": "/counter",
                                                      "type": "std_msgs/msg/Int32"}],
         "messages": [(0, {"data": v}) for v in range(1, COUNT + 1)], "period": 0.05},
        cwd=module_dir,
    )  # fmt: skip
    support.stop_recorder(recorder, signal.SIGINT)
    assert support.topic_counts(folder)["/counter"] == COUNT
    return folder


@pytest.fixture
def bag_copy(good_bag: Path, tmp_path: Path) -> Path:
    copy = tmp_path / good_bag.name
    shutil.copytree(good_bag, copy)
    return copy


def counter_values(folder: Path) -> list[int]:
    return [m.fields["data"] for m in support.by_topic(support.read_anyreader(folder))["/counter"]]


def test_a_folder_without_metadata_is_read_from_its_mcap_files(bag_copy: Path) -> None:
    (bag_copy / "metadata.yaml").unlink()
    result = support.rosl_run("bag", "info", str(bag_copy))
    assert result.returncode == 0, result.stderr
    assert (
        "Topic: /counter | Type: std_msgs/msg/Int32 | Count: 50 | Serialization Format: cdr"
        in result.stdout
    )
    (path,) = bag_copy.glob("*.mcap")
    assert f"{'Files:':<19}{path.name}" in result.stdout.splitlines()


def test_a_file_that_is_not_mcap_is_refused_with_one_line(tmp_path: Path) -> None:
    fake = tmp_path / "fake.mcap"
    fake.write_text("this is not a recording\n")
    line = support.one_line_error(support.rosl_run("bag", "info", str(fake)))
    assert "is not an MCAP file" in line
    assert "fake.mcap" in line
    folder = tmp_path / "fake_bag"
    folder.mkdir()
    shutil.copy(fake, folder / "fake_bag_0.mcap")
    line = support.one_line_error(support.rosl_run("bag", "info", str(folder)))
    assert "is not an MCAP file" in line


def test_metadata_naming_missing_files_is_reported_in_one_line_suggesting_reindex(
    bag_copy: Path,
) -> None:
    path = bag_copy / "metadata.yaml"
    data = yaml.safe_load(path.read_text())
    data["rosbag2_bagfile_information"]["relative_file_paths"].append("ghost_7.mcap")
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    line = support.one_line_error(support.rosl_run("bag", "info", str(bag_copy)))
    assert "ghost_7.mcap" in line
    assert "reindex" in line
    # and reindex indeed rebuilds the metadata from the files present
    result = support.rosl_run("bag", "reindex", str(bag_copy))
    assert result.returncode == 0, result.stderr
    assert "ghost_7.mcap" not in support.metadata(bag_copy)["relative_file_paths"]
    assert support.topic_counts(bag_copy)["/counter"] == COUNT
    assert counter_values(bag_copy) == list(range(1, COUNT + 1))


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("relative_file_paths", 5),
        ("relative_file_paths", [3]),
        ("topics_with_message_count", 3),
        ("topics_with_message_count", [{"topic_metadata": "x"}]),
        ("files", {"path": "x"}),
    ],
)
def test_metadata_of_the_wrong_shape_is_reported_in_one_line_naming_file_and_key(
    bag_copy: Path, key: str, value: object
) -> None:
    path = bag_copy / "metadata.yaml"
    data = yaml.safe_load(path.read_text())
    data["rosbag2_bagfile_information"][key] = value
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    for command in (["info"], ["info", "--json"], ["diff", str(bag_copy)]):
        line = support.one_line_error(support.rosl_run("bag", *command, str(bag_copy)))
        assert str(path) in line, line
        assert key in line, line


def test_a_truncated_mcap_is_reported_unfinished_and_reindex_keeps_its_complete_part(
    bag_copy: Path,
) -> None:
    from mcap.reader import make_reader

    (path,) = bag_copy.glob("*.mcap")
    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None
    original = support.read_mcap_file(path).messages
    cut = path.stat().st_size // 2
    complete = [c for c in summary.chunk_indexes if c.chunk_start_offset + c.chunk_length <= cut]
    assert complete, "the cut leaves no complete chunk; the recording is too small"
    last_complete = max(c.message_end_time for c in complete)
    must_keep = [m for m in original if m.log_time <= last_complete]
    with path.open("r+b") as handle:
        handle.truncate(cut)

    info = support.rosl_run("bag", "info", str(bag_copy))
    said = info.stdout + info.stderr
    assert "unfinished" in said
    assert "reindex" in said
    assert info.returncode == 0, said  # what is complete is shown; the repair is suggested
    assert "Traceback" not in said

    result = support.rosl_run("bag", "reindex", str(bag_copy))
    assert result.returncode == 0, result.stderr
    repaired = support.read_mcap_file(path).messages
    # exactly a prefix of the original, holding at least every message of a complete chunk
    assert [m.data for m in repaired] == [m.data for m in original[: len(repaired)]]
    assert len(repaired) >= len(must_keep)
    assert support.metadata(bag_copy)["message_count"] == len(repaired)
    # rosbags reads the repaired folder whole (it matches metadata.yaml's topics, QoS
    # included, with the file's channels)
    assert len(support.read_anyreader(bag_copy)) == len(repaired)
    assert len(support.read_rosbag2(bag_copy)) == len(repaired)
    values = counter_values(bag_copy)
    assert values == list(range(1, len(values) + 1))


# a recorder whose files may not grow past a limit: writes fail as on a full disk (EFBIG)
FULL_DISK = r"""
import os, resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (160000, 160000))  # about one second of /blob
os.execv(sys.executable, [sys.executable, "-m", "rosl", *sys.argv[1:]])
"""


@pytest.mark.slow
def test_recording_onto_a_full_disk_stops_with_one_line_and_claims_no_success(
    processes: Processes, tmp_path: Path
) -> None:
    folder = tmp_path / "full"
    recorder = support.Child(
        processes.python(FULL_DISK, "bag", "record", "-a", "-o", str(folder), cwd=tmp_path)
    )
    assert recorder.wait_for(support.RECORDING_TO, stream="err", timeout=30), recorder.both()
    blobs = [(0, {"data": f"{i:04d}" + "x" * 2000}) for i in range(1, 151)]
    publisher = support.start_publisher(
        processes,
        {"node": "full_talker", "publishers": [{"topic": "/blob", "type": "std_msgs/msg/String"}],
         "messages": blobs, "period": 0.02},
        cwd=tmp_path,
    )  # fmt: skip
    # the recorder gives up by itself once the disk is full, while messages keep coming
    code = recorder.finish(timeout=30)
    assert publisher.finish(30) == 0, publisher.both()
    assert code == 1, recorder.both()
    err = recorder.text["err"].strip().splitlines()
    assert "Traceback" not in recorder.text["err"]
    assert "Recording stopped" not in recorder.text["err"]
    assert "full_0.mcap" in err[-1] or str(folder) in err[-1], err[-1]
    assert not (folder / "metadata.yaml").exists()
    # what reached the disk can be repaired: a prefix of what was sent
    result = support.rosl_run("bag", "reindex", str(folder))
    assert result.returncode == 0, result.stderr
    found = support.by_topic(support.read_anyreader(folder)).get("/blob", [])
    assert found, "nothing of the recording survived the full disk"
    assert [m.data for m in found] == [
        support.cdr("std_msgs/msg/String", fields) for _, fields in blobs[: len(found)]
    ]
