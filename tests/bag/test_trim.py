"""``rosl bag filter`` and ``convert``: new bags holding a selection, bytes unchanged."""

from __future__ import annotations

from typing import TYPE_CHECKING

import yaml
from rosbags.highlevel import AnyReader
from rosbags.rosbag2 import Reader

from rosl.cli.main import main
from tests.bag.conftest import TYPES, mcap_messages, torn_bag

if TYPE_CHECKING:
    from pathlib import Path

    import pytest

NS = 1_000_000_000


def run(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[int, str, str]:
    code = main(["bag", *[str(a) for a in args]])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def channel_hashes(bag: Path) -> dict[str, str]:
    from tests.bag_record.support import channel_hashes as hashes

    return hashes(bag)


def _topics(bag: Path) -> dict[str, dict]:
    information = yaml.safe_load((bag / "metadata.yaml").read_text())
    return {
        entry["topic_metadata"]["name"]: {
            **entry["topic_metadata"],
            "count": entry["message_count"],
        }
        for entry in information["rosbag2_bagfile_information"]["topics_with_message_count"]
    }


def _any_reader_messages(bag: Path) -> list[tuple[str, int, bytes]]:
    with AnyReader([bag]) as reader:
        return [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]


def test_filter_keeps_only_the_chosen_topics_inside_the_time_window(capsys, scenario_bag, tmp_path):
    source = mcap_messages(scenario_bag)
    start = source[0].log_time
    pose = [m.log_time - start for m in source if m.topic == "/pose"][1] / NS  # recorded times
    window = (pose - 0.05, pose + 0.15)  # the second /pose, and /chatter m2 and m3
    out_bag = tmp_path / "window"
    code, out, _ = run(
        capsys, "filter", scenario_bag, out_bag, "--topics", "/chatter", "/pose",
        "--start", f"{window[0]:.9f}", "--end", f"{window[1]:.9f}",
    )  # fmt: skip
    assert code == 0
    kept = [
        m for m in source
        if m.topic in ("/chatter", "/pose")
        and start + window[0] * NS <= m.log_time <= start + window[1] * NS
    ]  # fmt: skip
    assert {m.topic for m in kept} == {"/chatter", "/pose"}
    assert mcap_messages(out_bag) == kept  # bytes, log/publish times and sequences kept
    assert f"wrote {len(kept)} of {len(source)} messages on 2 topics" in out
    assert _any_reader_messages(out_bag) == [(m.topic, m.log_time, m.data) for m in kept]
    with Reader(out_bag) as reader:
        assert {c.topic: c.msgtype for c in reader.connections} == {
            "/chatter": TYPES["/chatter"], "/pose": TYPES["/pose"]
        }  # fmt: skip
        assert reader.message_count == len(kept)
    before, after = _topics(scenario_bag), _topics(out_bag)
    for name in ("/chatter", "/pose"):
        assert after[name]["offered_qos_profiles"] == before[name]["offered_qos_profiles"]
        assert channel_hashes(out_bag)[name] == channel_hashes(scenario_bag)[name] != ""
        assert after[name]["count"] == sum(1 for m in kept if m.topic == name)


def test_filter_exclude_drops_the_matching_topics(capsys, scenario_bag, tmp_path):
    out_bag = tmp_path / "no_numbers"
    assert (
        run(capsys, "filter", scenario_bag, out_bag, "--exclude", "^/(numbers|parameter)")[0] == 0
    )
    assert {m.topic for m in mcap_messages(out_bag)} == {"/chatter", "/pose"}


def test_convert_to_zstd_reads_back_byte_identical_messages(capsys, scenario_bag, tmp_path):
    from mcap.reader import make_reader

    out_bag = tmp_path / "packed"
    code, out, _ = run(capsys, "convert", scenario_bag, out_bag, "--compression-format", "zstd")
    assert code == 0
    assert "(zstd)" in out
    with next(out_bag.glob("*.mcap")).open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert {index.compression for index in summary.chunk_indexes} == {"zstd"}
    assert _any_reader_messages(out_bag) == _any_reader_messages(scenario_bag)
    assert mcap_messages(out_bag) == mcap_messages(scenario_bag)
    unpacked = tmp_path / "unpacked"
    assert run(capsys, "convert", out_bag, unpacked, "--compression-format", "lz4")[0] == 0
    assert mcap_messages(unpacked) == mcap_messages(scenario_bag)


def test_filter_refuses_an_output_folder_that_holds_files(capsys, scenario_bag, tmp_path):
    taken = tmp_path / "taken"
    taken.mkdir()
    (taken / "something").write_text("x")
    code, _, err = run(capsys, "filter", scenario_bag, taken, "--topics", "/chatter")
    assert code == 1
    assert err.strip() == f"Output folder '{taken}' already exists and is not empty"


def test_filter_of_a_bag_whose_metadata_names_missing_files_says_so(capsys, scenario_bag, tmp_path):
    import shutil

    broken = tmp_path / "broken"
    shutil.copytree(scenario_bag, broken)
    for path in broken.glob("*.mcap"):
        path.unlink()
    code, _, err = run(capsys, "filter", broken, tmp_path / "out")
    assert code == 1
    assert "names files that are not there" in err
    assert len(err.strip().splitlines()) == 1


def test_convert_of_an_unfinished_file_warns_and_writes_its_complete_messages(
    capsys, scenario_bag, tmp_path
):
    torn = torn_bag(scenario_bag, tmp_path / "torn")
    code, out, err = run(capsys, "convert", torn, tmp_path / "whole")
    assert code == 0
    assert "is unfinished" in err
    assert "rosl bag reindex" in err
    assert "wrote 4 of 4 messages on 1 topics" in out
    chatter = mcap_messages(scenario_bag, {"/chatter"})[:4]
    assert [m.data for m in mcap_messages(tmp_path / "whole")] == [m.data for m in chatter]
    assert len(_any_reader_messages(tmp_path / "whole")) == 4


def test_filter_windows_count_from_the_first_message_held_not_from_the_statistics(capsys, tmp_path):
    from tests.bag.test_info_options import zero_start_bag

    source = zero_start_bag(tmp_path / "zero")  # messages at 0, 1, 2 s; Statistics say 1 s
    out = tmp_path / "after_half"
    code, _, err = run(capsys, "filter", source, out, "--start", "0.5")
    assert code == 0, err
    assert [m.log_time for m in mcap_messages(out)] == [NS, 2 * NS]


def test_a_finished_file_without_statistics_is_converted_without_an_unfinished_warning(
    capsys, tmp_path
):
    from mcap.writer import Writer

    from tests.bag.test_info_options import cdr_string

    folder = tmp_path / "nostats"
    folder.mkdir()
    with (folder / "nostats.mcap").open("wb") as handle:
        writer = Writer(handle, use_statistics=False)
        writer.start(profile="ros2", library="outside writer")
        schema = writer.register_schema("std_msgs/msg/String", "ros2msg", b"string data\n")
        channel = writer.register_channel("/said", "cdr", schema)
        for k in range(3):
            writer.add_message(channel, (k + 1) * NS, cdr_string(f"s{k}"), (k + 1) * NS)
        writer.finish()
    code, _, err = run(capsys, "convert", folder, tmp_path / "out")
    assert code == 0, err
    assert "unfinished" not in err
    assert [m.log_time for m in mcap_messages(tmp_path / "out")] == [NS, 2 * NS, 3 * NS]
