"""Fixtures of the launch tests: examples on the package path, a log folder, a rosl runner."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from tests.launch.support import EXAMPLES, Rosl

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from tests.conftest import Processes


@pytest.fixture
def log_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """ROSL_LOG_DIR for the launcher; the examples on ROSL_PACKAGE_PATH; no NO_COLOR."""
    folder = tmp_path / "log"
    monkeypatch.setenv("ROSL_LOG_DIR", str(folder))
    monkeypatch.setenv("ROSL_PACKAGE_PATH", str(EXAMPLES))
    monkeypatch.delenv("NO_COLOR", raising=False)
    return folder


@pytest.fixture
def rosl(processes: Processes, log_dir: Path) -> Iterator[Rosl]:
    """Run rosl commands as processes; any launched pid left alive is killed afterwards."""
    runner = Rosl(processes)
    try:
        yield runner
    finally:
        runner.close()


@pytest.fixture
def launch_dir(tmp_path: Path) -> Path:
    """A folder for the test's launch files and helper scripts."""
    folder = tmp_path / "launch_files"
    folder.mkdir()
    return folder
