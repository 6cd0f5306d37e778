"""``rosl bag diff``: topic by topic, in order, field by field with a tolerance."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import pytest

from rosl.cli.main import main
from tests.bag.conftest import edit_field, rewrite

if TYPE_CHECKING:
    from pathlib import Path


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str, str]:
    code = main(["bag", "diff", *[str(a) for a in args]])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _move_pose(by: float):
    def edit(record):
        if record.topic != "/pose" or b"map" not in record.data:
            return record

        def shift(message):
            if message.pose.position.x == 1.0:
                message.pose.position.x += by

        return edit_field(record, shift)

    return edit


def test_diff_of_a_bag_with_itself_matches(capsys, scenario_bag):
    code, out, _ = run(capsys, scenario_bag, scenario_bag)
    assert code == 0
    assert out.strip().startswith("bags match: ")
    assert "on 4 topics" in out


def test_diff_names_topic_index_field_and_both_values_beyond_the_tolerance(
    capsys, scenario_bag, tmp_path
):
    changed = rewrite(scenario_bag, tmp_path / "new", _move_pose(0.0156))
    code, out, _ = run(capsys, scenario_bag, changed)
    assert code == 1
    lines = out.strip().splitlines()
    assert lines[0] == "/pose #1 pose.position.x: 1.0 vs 1.0156 (|d|=0.0156 > 0.001)"
    assert lines[-1] == "bags differ: 1 difference(s)"


def test_diff_accepts_a_change_within_the_tolerance(capsys, scenario_bag, tmp_path):
    changed = rewrite(scenario_bag, tmp_path / "new", _move_pose(0.0004))
    assert run(capsys, scenario_bag, changed)[0] == 0
    code, out, _ = run(capsys, scenario_bag, changed, "--tolerance", "1e-5")
    assert code == 1
    assert "pose.position.x" in out


def test_diff_ignore_field_lets_stamp_only_differences_pass(capsys, scenario_bag, tmp_path):
    def later(record):
        if record.topic != "/pose":
            return record
        return edit_field(record, lambda m: setattr(m.header.stamp, "sec", m.header.stamp.sec + 1))

    changed = rewrite(scenario_bag, tmp_path / "new", later)
    code, out, _ = run(capsys, scenario_bag, changed)
    assert code == 1
    assert "/pose #0 header.stamp.sec: " in out
    assert "bags differ: 3 difference(s)" in out
    assert run(capsys, scenario_bag, changed, "--ignore-field", "header.stamp")[0] == 0


def test_diff_reports_a_missing_topic_and_an_extra_one(capsys, scenario_bag, tmp_path):
    def rename(record):
        if record.topic == "/numbers":
            return None
        return record

    changed = rewrite(scenario_bag, tmp_path / "new", rename)
    code, out, _ = run(capsys, scenario_bag, changed)
    assert code == 1
    assert "/numbers: missing from new (golden has 3 messages)" in out
    code, out, _ = run(capsys, changed, scenario_bag)
    assert code == 1
    assert "/numbers: only in new (3 messages)" in out
    assert run(capsys, scenario_bag, changed, "--topics", "/chatter", "/pose")[0] == 0


def test_diff_reports_counts_and_changed_strings(capsys, scenario_bag, tmp_path):
    def edit(record):
        if record.topic != "/chatter":
            return record
        if record.data.endswith(b"m4\x00"):
            return None
        if record.data.endswith(b"m2\x00"):
            return edit_field(record, lambda m: setattr(m, "data", "changed"))
        return record

    changed = rewrite(scenario_bag, tmp_path / "new", edit)
    code, out, _ = run(capsys, scenario_bag, changed)
    assert code == 1
    assert "/chatter: 5 messages in golden vs 4 in new" in out
    assert "/chatter #2 data: 'm2' vs 'changed'" in out


def test_diff_checks_timing_only_with_a_time_tolerance(capsys, scenario_bag, tmp_path):
    def delay(record):
        if record.topic == "/numbers" and record.data.endswith(b"\x02\x00\x00\x00"):
            return dataclasses.replace(record, log_time=record.log_time + 200_000_000)
        return record

    changed = rewrite(scenario_bag, tmp_path / "new", delay)
    assert run(capsys, scenario_bag, changed)[0] == 0
    code, out, _ = run(capsys, scenario_bag, changed, "--time-tolerance", "0.05")
    assert code == 1
    assert "/numbers #1 log time: " in out
    assert "(|d|=0.2 s > 0.05 s)" in out


def test_diff_decodes_a_type_unknown_here_from_the_bag_schema(capsys, tmp_path):
    from mcap.writer import Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    text = "float64 value\nstring label\nint32[] counts\n"
    store = get_typestore(Stores.EMPTY)
    store.register(get_types_from_msg(text, "unknown_pkg/msg/Reading"))
    reading = store.types["unknown_pkg/msg/Reading"]

    def write(folder: Path, value: float, counts: list[int]) -> Path:
        import numpy as np

        folder.mkdir()
        with (folder / f"{folder.name}_0.mcap").open("wb") as handle:
            writer = Writer(handle)
            writer.start(profile="ros2", library="test")
            schema = writer.register_schema("unknown_pkg/msg/Reading", "ros2msg", text.encode())
            channel = writer.register_channel("/reading", "cdr", schema)
            for index in range(3):
                message = reading(value=value * index, label="a", counts=np.array(counts, np.int32))
                data = store.serialize_cdr(message, "unknown_pkg/msg/Reading")
                writer.add_message(channel, index * 1000, bytes(data), index * 1000)
            writer.finish()
        return folder

    golden = write(tmp_path / "golden", 1.0, [1, 2, 3])
    new = write(tmp_path / "new", 1.5, [1, 2, 4])
    code, out, _ = run(capsys, golden, new)
    assert code == 1
    assert "/reading #1 value: 1.0 vs 1.5 (|d|=0.5 > 0.001)" in out
    assert "/reading #0 counts[2]: 3 vs 4" in out


@pytest.mark.parametrize(
    ("layout", "expected"),
    [("missing", "no recording at"), ("not_mcap", "is not an MCAP file")],
)
def test_diff_of_a_bad_bag_says_so_in_one_line(capsys, scenario_bag, tmp_path, layout, expected):
    target = tmp_path / "bag.mcap"
    if layout == "not_mcap":
        target.write_text("not a bag")
    code, out, err = run(capsys, scenario_bag, target)
    assert code == 1
    assert expected in err
    assert len(err.strip().splitlines()) == 1
    assert out == ""
