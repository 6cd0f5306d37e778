"""The bus's numeric settings: a number from the environment, the default for anything else."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from rosl.bus.fragment import BUDGET_MB, budget_from_env
from rosl.bus.multicast import BACKLOG_MS, backlog_from_env
from rosl.bus.settings import env_number


@pytest.mark.parametrize(("text", "expected"), [("250", 250.0), (" 0.5 ", 0.5), ("1e3", 1000.0)])
def test_a_number_in_the_environment_is_taken(monkeypatch, text, expected):
    monkeypatch.setenv("ROSL_TEST_SETTING", text)
    assert env_number("ROSL_TEST_SETTING", 7.0) == expected


@pytest.mark.parametrize("text", ["", "   ", "fast", "12ms", "inf", "-inf", "nan"])
def test_an_unset_or_unreadable_setting_is_the_default(monkeypatch, text):
    monkeypatch.setenv("ROSL_TEST_SETTING", text)
    assert env_number("ROSL_TEST_SETTING", 7.0) == 7.0


def test_the_backlog_bound_is_in_milliseconds_and_never_negative(monkeypatch):
    monkeypatch.setenv("ROSL_BACKLOG_MS", "250")
    assert backlog_from_env() == 250_000_000
    monkeypatch.setenv("ROSL_BACKLOG_MS", "-5")
    assert backlog_from_env() == 0
    monkeypatch.setenv("ROSL_BACKLOG_MS", "soon")
    assert backlog_from_env() == BACKLOG_MS * 1_000_000


def test_the_reassembly_budget_still_reads_megabytes(monkeypatch):
    monkeypatch.setenv("ROSL_REASSEMBLY_MB", "2")
    assert budget_from_env() == 2 * 1024 * 1024
    monkeypatch.setenv("ROSL_REASSEMBLY_MB", "lots")
    assert budget_from_env() == BUDGET_MB * 1024 * 1024


@pytest.mark.parametrize("name", ["ROSL_BACKLOG_MS", "ROSL_REASSEMBLY_MB"])
def test_an_infinite_setting_is_the_default_in_a_command(domain_id, name):
    done = subprocess.run(
        [sys.executable, "-m", "rosl", "topic", "list"],
        capture_output=True, text=True, timeout=60, check=False,
        env={**os.environ, name: "inf"},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
