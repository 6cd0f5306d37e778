"""Ways to run the ``rosl`` command line: in this process (fast) or as a real process."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from rosl.cli.main import main
from rosl.idl import registry
from tests.conftest import ChildOutput

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.graph.cache import GraphCache
    from tests.conftest import Processes


@dataclass(frozen=True)
class Result:
    """What one run of ``rosl`` gave back."""

    code: int
    out: str
    err: str

    @property
    def err_lines(self) -> list[str]:
        return self.err.splitlines()


def assert_user_error(result: Result, *fragments: str) -> str:
    """Check the shape of a user mistake: exit 1, one stderr line, no traceback."""
    assert result.code == 1, result
    assert "Traceback" not in result.out + result.err
    assert len(result.err_lines) == 1, result.err
    line = result.err_lines[0]
    for fragment in fragments:
        assert fragment in line, line
    return line


@pytest.fixture
def rosl(capsys: pytest.CaptureFixture[str]) -> Callable[..., Result]:
    """Run ``rosl ARGS`` in this process (fresh caches) and capture what it prints."""

    def run(*args: str) -> Result:
        registry.clear()
        capsys.readouterr()
        code = main(list(args))
        captured = capsys.readouterr()
        return Result(code, captured.out, captured.err)

    return run


@pytest.fixture
def rosl_process() -> Callable[..., Result]:
    """Run the real ``rosl`` (``python -m rosl``) as a process."""

    def run(*args: str, cwd: Path | None = None, stdin: str | None = None) -> Result:
        env = dict(os.environ)
        env["NO_COLOR"] = "1"
        done = subprocess.run(
            [sys.executable, "-m", "rosl", *args],
            cwd=cwd or Path.cwd(),
            input=stdin if stdin is not None else "",
            capture_output=True,
            text=True,
            timeout=60,
            env=env,
            check=False,
        )
        return Result(done.returncode, done.stdout, done.stderr)

    return run


def run(processes: Processes, *args: str, timeout: float = 30.0) -> Result:
    """Run the real ``rosl ARGS`` on the test's domain, piped (ROS 2's plain text); bounded."""
    child = processes.rosl(*args, env={"NO_COLOR": "1"})
    out, err = child.communicate(timeout=timeout)
    return Result(child.returncode, out, err)


def timed(processes: Processes, *args: str) -> tuple[Result, float]:
    """:func:`run`, and how long it took in seconds."""
    started = time.monotonic()
    result = run(processes, *args)
    return result, time.monotonic() - started


def timed_after(
    processes: Processes, marker: str, *args: str, timeout: float = 60.0
) -> tuple[Result, float, float]:
    """:func:`run`, how long it took, and how long it still ran after printing ``marker``.

    The second time leaves out the interpreter's start-up (seconds on a loaded machine), so a
    bound on it can tell a wait of 1 s from one of 5 s without depending on the machine's speed.
    """
    started = time.monotonic()
    child = processes.rosl(*args, env={"NO_COLOR": "1"})
    output = ChildOutput(child)
    deadline = started + timeout
    marked: float | None = None
    while output._open and (left := deadline - time.monotonic()) > 0:
        output._read(min(left, 0.02))
        if marked is None and marker in output.text["out"]:
            marked = time.monotonic()
    child.wait(timeout=max(0.1, deadline - time.monotonic()))
    ended = time.monotonic()
    assert marked is not None, f"{marker!r} never printed: {output.text}"
    result = Result(child.returncode, output.text["out"], output.text["err"])
    return result, ended - started, ended - marked


def wait_graph(check: Callable[[GraphCache], bool], timeout: float = 30.0) -> None:
    """Wait, from a bare participant that shows up nowhere, until the graph passes ``check``."""
    from rosl.introspection.session import Session

    with Session() as session:
        graph = session.graph()
        assert graph.wait_for(lambda: check(graph), timeout), [n.fqn for n in graph.nodes()]
