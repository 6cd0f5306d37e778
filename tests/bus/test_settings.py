"""The bus's numeric settings: a number from the environment, one line naming a bad one."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from rosl.bus.errors import BusError
from rosl.bus.fragment import BUDGET_MB, budget_from_env
from rosl.bus.multicast import BACKLOG_MS, backlog_from_env
from rosl.bus.settings import env_number


@pytest.mark.parametrize(("text", "expected"), [("250", 250.0), (" 0.5 ", 0.5), ("1e3", 1000.0)])
def test_a_number_in_the_environment_is_taken(monkeypatch, text, expected):
    monkeypatch.setenv("ROSL_TEST_SETTING", text)
    assert env_number("ROSL_TEST_SETTING", 7.0, "things") == expected


@pytest.mark.parametrize("text", ["", "   "])
def test_an_unset_setting_is_the_default(monkeypatch, text):
    monkeypatch.setenv("ROSL_TEST_SETTING", text)
    assert env_number("ROSL_TEST_SETTING", 7.0, "things") == 7.0


@pytest.mark.parametrize("text", ["fast", "12ms", "inf", "-inf", "nan", "-1"])
def test_a_bad_setting_is_an_error_naming_it(monkeypatch, text):
    monkeypatch.setenv("ROSL_TEST_SETTING", text)
    with pytest.raises(BusError) as caught:
        env_number("ROSL_TEST_SETTING", 7.0, "things")
    assert str(caught.value) == (
        f"ROSL_TEST_SETTING={text!r} is not a number of things from 0 (unset: 7)"
    )


def test_the_backlog_bound_is_in_milliseconds(monkeypatch):
    monkeypatch.setenv("ROSL_BACKLOG_MS", "250")
    assert backlog_from_env() == 250_000_000
    monkeypatch.setenv("ROSL_BACKLOG_MS", "0")
    assert backlog_from_env() == 0
    monkeypatch.delenv("ROSL_BACKLOG_MS")
    assert backlog_from_env() == BACKLOG_MS * 1_000_000


def test_the_reassembly_budget_reads_megabytes_from_one(monkeypatch):
    monkeypatch.setenv("ROSL_REASSEMBLY_MB", "2")
    assert budget_from_env() == 2 * 1024 * 1024
    monkeypatch.delenv("ROSL_REASSEMBLY_MB")
    assert budget_from_env() == BUDGET_MB * 1024 * 1024
    monkeypatch.setenv("ROSL_REASSEMBLY_MB", "0.5")
    with pytest.raises(BusError, match="from 1 "):
        budget_from_env()


@pytest.mark.parametrize(
    ("name", "value"),
    [("ROSL_BACKLOG_MS", "inf"), ("ROSL_BACKLOG_MS", "soon"), ("ROSL_REASSEMBLY_MB", "lots")],
)
def test_a_bad_setting_in_a_command_is_one_line_and_exit_1(domain_id, name, value):
    done = subprocess.run(
        [sys.executable, "-m", "rosl", "topic", "list"],
        capture_output=True, text=True, timeout=60, check=False,
        env={**os.environ, "ROS_DOMAIN_ID": str(domain_id), name: value},
    )  # fmt: skip
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith(f"{name}={value!r} is not a number of "), lines


LEAK_CHECK = """
import os, sys
from rosl.bus.errors import BusError
from rosl.node.participant import Participant

before = sorted(os.listdir("/proc/self/fd"))
for _ in range(3):
    try:
        Participant(int(sys.argv[1]))
    except BusError as err:
        print("refused:", err)
print("open before", len(before), "after", len(os.listdir("/proc/self/fd")))
"""


def test_a_participant_refused_for_a_bad_setting_leaves_nothing_open(domain_id):
    # a library user may catch the error and go on: no socket, pipe or ring left behind
    done = subprocess.run(
        [sys.executable, "-c", LEAK_CHECK, str(domain_id)],
        capture_output=True, text=True, timeout=60, check=False,
        env={**os.environ, "ROSL_BACKLOG_MS": "soon"},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("refused: ROSL_BACKLOG_MS='soon' is not a number"), lines
    before, after = lines[-1].split()[2], lines[-1].split()[4]
    assert after == before, lines
