"""Bags that are damaged, odd or half-written: one line for each, and nothing lost or left over.

Every bag here is written by the ``mcap`` library (an outside writer) or is a rosl bag damaged
on purpose; the commands run in this process through the CLI's ``main``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import yaml

from rosl.bag import metadata
from rosl.bag.writer import BagFile
from rosl.cli.main import main
from tests.bag.test_info_options import BASE, NS, cdr_string, json_bag, write_mcap

if TYPE_CHECKING:
    from pathlib import Path

    import pytest


def run(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def said(folder: Path, count: int = 3) -> Path:
    """A folder with one MCAP file of /said (std_msgs/msg/String), written by the mcap library."""
    folder.mkdir()
    write_mcap(
        folder / "said.mcap",
        [
            ("/said", "std_msgs/msg/String", BASE + k * NS, cdr_string(f"s{k}"))
            for k in range(count)
        ],
    )
    return folder


def test_a_new_file_is_mcap_on_disk_before_its_first_message(tmp_path: Path) -> None:
    path = tmp_path / "started.mcap"
    started = BagFile(path)  # open, as in a recorder killed now (never flushed, never finished)
    assert path.read_bytes().startswith(b"\x89MCAP0\r\n")
    assert len(path.read_bytes()) > 8  # the header record too
    started.abandon()


def test_reindex_leaves_out_empty_and_messageless_files_and_keeps_the_rest(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    folder = said(tmp_path / "run")
    (folder / "said.mcap").rename(folder / "run_0.mcap")
    (folder / "run_1.mcap").write_bytes(b"")  # killed before it wrote a byte
    BagFile(folder / "run_2.mcap").abandon()  # killed after its header
    code, out, err = run(capsys, "bag", "reindex", folder)
    assert code == 0, err
    assert "run_1.mcap: empty (its recorder stopped before writing); left out" in out
    assert "run_2.mcap: holds no complete message" in out
    listed = metadata.read(folder)
    assert listed["relative_file_paths"] == ["run_0.mcap"]
    assert listed["message_count"] == 3
    code, out, err = run(capsys, "bag", "info", folder)  # and the folder reads
    assert code == 0, err


def test_reindex_keeps_custom_data_and_the_old_metadata_when_it_names_a_file_left_out(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    folder = said(tmp_path / "run")
    (folder / "said.mcap").rename(folder / "run_0.mcap")
    BagFile(folder / "run_1.mcap").abandon()
    infos = [
        metadata.FileInfo("run_0.mcap", BASE, BASE + 2 * NS, 3),
        metadata.FileInfo("run_1.mcap"),
    ]
    topic = metadata.TopicInfo("/said", "std_msgs/msg/String", count=3)
    metadata.write(folder, [topic], infos, {"operator": "ada"})
    old = (folder / "metadata.yaml").read_text()
    code, out, err = run(capsys, "bag", "reindex", folder)
    assert code == 0, err
    assert "kept as metadata.yaml.orig" in out
    assert (folder / "metadata.yaml.orig").read_text() == old
    assert metadata.read(folder)["custom_data"] == {"operator": "ada"}


def test_reindex_of_db3_files_says_they_need_none(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    folder = tmp_path / "lite"
    folder.mkdir()
    (folder / "lite_0.db3").write_bytes(b"SQLite format 3\x00")
    code, _, err = run(capsys, "bag", "reindex", folder)
    assert code == 1
    assert err.strip() == (
        f"'{folder}' holds rosbag2 sqlite3 files (lite_0.db3): they need no reindex; "
        "reindex repairs folders of .mcap files"
    )


def test_a_damaged_compressed_chunk_is_one_line_that_names_the_repair(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from mcap.reader import make_reader

    source = said(tmp_path / "plain", count=200)
    packed = tmp_path / "packed"
    assert run(capsys, "bag", "convert", source, packed, "--compression-format", "zstd")[0] == 0
    (path,) = packed.glob("*.mcap")
    with path.open("rb") as handle:
        (chunk,) = make_reader(handle).get_summary().chunk_indexes
    data = bytearray(path.read_bytes())
    middle = chunk.chunk_start_offset + chunk.chunk_length - chunk.compressed_size // 2
    data[middle : middle + 8] = bytes(8)  # inside its compressed records
    path.write_bytes(bytes(data))
    for command in (["info", "-v"], ["filter", "--topics", "/said"], ["play", "-r", "100"]):
        words = [command[0], packed, *([tmp_path / "out"] if command[0] == "filter" else [])]
        code, _, err = run(capsys, "bag", *words, *command[1:])
        assert code == 1, (command, err)
        lines = [line for line in err.strip().splitlines() if not line.startswith("[INFO]")]
        assert len(lines) == 1, err  # (play says what it starts to play first)
        assert "Traceback" not in err
        assert f"rosl bag reindex {packed} --keep-corrupt" in lines[0], lines[0]
    assert not (tmp_path / "out").exists()  # nothing half-written is left


def test_qos_profiles_of_any_shape_read_as_profiles(tmp_path: Path) -> None:
    odd = [{"depth": "abc", "reliability": "sometimes", "durability": None,
            "deadline": {"sec": "x", "nsec": 1}, "liveliness": 99}]  # fmt: skip
    (profile,) = metadata.parse_profiles(yaml.safe_dump(odd))
    assert profile["depth"] == 0
    assert (profile["reliability"], profile["durability"]) == ("unknown", "system_default")
    assert profile["liveliness"] == "unknown"
    assert profile["deadline"] == {"sec": 9223372036854775807, "nsec": 4294967295}


def test_filter_can_leave_out_a_topic_it_could_not_convert(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    source = json_bag(tmp_path / "mixed")
    code, out, err = run(capsys, "bag", "filter", source, tmp_path / "out", "--exclude", "/data")
    assert code == 0, err
    assert "wrote 1 of 2 messages on 1 topics" in out


def test_an_output_inside_its_input_is_refused(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    source = said(tmp_path / "run")
    code, _, err = run(capsys, "bag", "convert", source, source / "inside")
    assert code == 1
    assert "would overwrite the input" in err
    assert not (source / "inside").exists()


def test_an_environment_of_another_distro_records_humbles_layout(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("ROS_DISTRO", "noetic")
    assert metadata.distro() == "humble"
    monkeypatch.setenv("ROS_DISTRO", "Jazzy")
    assert metadata.distro() == "jazzy"
