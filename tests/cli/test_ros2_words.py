"""The rest of ``ros2``'s commands: daemon (none needed), wtf (doctor), and the ones not there yet."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import pytest

from tests.cli.conftest import assert_user_error, run

if TYPE_CHECKING:
    from tests.conftest import Processes


@pytest.mark.parametrize(
    ("verb", "line"),
    [
        ("start", "There is no daemon to start"),
        ("stop", "There is no daemon to stop"),
        ("status", "The daemon is not running"),
    ],
)
def test_daemon_verbs_say_in_one_line_that_rosl_needs_none_and_succeed(
    processes: Processes, verb: str, line: str
) -> None:
    result = run(processes, "daemon", verb)

    assert result.code == 0, result  # a ROS 2 script's `ros2 daemon stop` goes on
    assert result.err == ""
    lines = result.out.splitlines()
    assert len(lines) == 1, result.out
    assert lines[0].startswith(line)
    assert "each command asks the live graph" in lines[0]


def test_daemon_start_takes_ros2s_debug_flag(processes: Processes) -> None:
    result = run(processes, "daemon", "start", "--debug")

    assert result.code == 0, result
    assert result.out.startswith("There is no daemon to start")


def test_wtf_is_doctor(processes: Processes) -> None:
    wtf = run(processes, "wtf", timeout=60)
    doctor = run(processes, "doctor", timeout=60)

    assert wtf.code == doctor.code == 0, wtf.out + wtf.err
    checks = [re.sub(r"\].*", "]", line) for line in wtf.out.splitlines()]
    assert checks == [re.sub(r"\].*", "]", line) for line in doctor.out.splitlines()]
    assert any(line.startswith("[ OK ] domain: ") for line in wtf.out.splitlines()), wtf.out
    assert run(processes, "wtf", "--help").out.startswith("Usage: rosl wtf [OPTIONS]")


@pytest.mark.parametrize(
    ("words", "line"),
    [
        (["component", "list"], "rosl component list: components are not in rosl"),
    ],
    ids=["component-list"],
)
def test_commands_not_there_yet_say_so_in_one_line_and_fail(
    processes: Processes, words: list[str], line: str
) -> None:
    result = run(processes, *words)

    assert result.out == ""
    assert_user_error(result, line)
