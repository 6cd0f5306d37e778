"""The tree stays clean: ``ruff check`` and ``mypy --strict`` report nothing.

Both run as pyproject.toml configures them (ruff over the repository, mypy over the ``rosl``
package), from the interpreter running the tests, so CI checks what a developer checks.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import REPO


def _run_module(args: list[str]) -> subprocess.CompletedProcess[str]:
    """Run ``python -m <args>`` in the repository; the child is killed if it overruns."""
    return subprocess.run(
        [sys.executable, "-m", *args],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=540,
        check=False,
    )


@pytest.mark.timeout(600)
def test_ruff_check_reports_nothing() -> None:
    result = _run_module(["ruff", "check", "--no-fix", "--output-format", "concise", "."])
    if result.returncode != 0:
        pytest.fail(f"ruff check reported problems:\n{result.stdout}{result.stderr}", pytrace=False)


@pytest.mark.timeout(600)
def test_mypy_strict_reports_nothing() -> None:
    # no targets: the config's ``packages = ["rosl"]`` says what to check; the cache is the
    # default .mypy_cache in the repository (ignored by git)
    result = _run_module(["mypy", "--strict", "--config-file", str(REPO / "pyproject.toml")])
    if result.returncode != 0:
        pytest.fail(
            f"mypy --strict reported problems:\n{result.stdout}{result.stderr}", pytrace=False
        )
