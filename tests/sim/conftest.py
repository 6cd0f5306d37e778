"""Helpers for the simulator's tests: world files, stepping on sim time, rosl as processes."""

from __future__ import annotations

import textwrap
from typing import TYPE_CHECKING

import pytest

from tests.launch.support import EXAMPLES, Rosl

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from rosl.sim.simulation import Simulation
    from tests.conftest import Processes

NS = 1_000_000_000


def run_until(sim: Simulation, t_ns: int) -> None:
    """Step ``sim`` until its clock reaches ``t_ns`` (bounded by the clock itself)."""
    while sim.now_ns < t_ns:
        sim.step()


@pytest.fixture
def write_world(tmp_path: Path) -> Callable[..., Path]:
    """Write a world file (text dedented) into a fresh folder; optional robot files beside it."""

    def write(text: str, name: str = "world.yaml", robots: dict[str, str] | None = None) -> Path:
        folder = tmp_path / "worlds"
        folder.mkdir(exist_ok=True)
        for model, source in (robots or {}).items():
            (folder / "robots").mkdir(exist_ok=True)
            (folder / "robots" / f"{model}.yaml").write_text(textwrap.dedent(source).lstrip())
        path = folder / name
        path.write_text(textwrap.dedent(text).lstrip(), encoding="utf-8")
        return path

    return write


@pytest.fixture
def rosl(processes: Processes, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Rosl]:
    """rosl commands as processes on the test's domain; launched children end by pid."""
    monkeypatch.setenv("ROSL_LOG_DIR", str(tmp_path / "log"))
    monkeypatch.setenv("ROSL_PACKAGE_PATH", str(EXAMPLES))
    monkeypatch.setenv("NO_COLOR", "1")
    runner = Rosl(processes)
    try:
        yield runner
    finally:
        runner.close()


def read_bag(folder: Path, *topics: str) -> list[tuple[str, int, object]]:
    """(topic, log time, message) of every message on ``topics`` in a rosbag2 folder."""
    from rosbags.highlevel import AnyReader

    out = []
    with AnyReader([folder]) as reader:
        wanted = [c for c in reader.connections if c.topic in topics]
        for connection, log_time, raw in reader.messages(connections=wanted):
            out.append((connection.topic, log_time, reader.deserialize(raw, connection.msgtype)))
    return out


def raw_bag(folder: Path) -> list[tuple[str, int, bytes]]:
    """(topic, log time, CDR bytes) of every message in a rosbag2 folder, in log order."""
    from rosbags.highlevel import AnyReader

    with AnyReader([folder]) as reader:
        return [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]


def stamp_ns(header: object) -> int:
    """A message header's stamp in nanoseconds."""
    stamp = header.stamp  # type: ignore[attr-defined]
    return int(stamp.sec) * NS + int(stamp.nanosec)
