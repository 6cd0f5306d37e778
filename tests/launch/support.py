"""Helpers for launch tests: read a child's output with select and deadlines, check pids.

Every wait is bounded. A launched process is identified by the pid the launcher prints in
``[INFO] [name-N]: process started with pid [PID]``; at the end of a test each such pid must
be gone.
"""

from __future__ import annotations

import contextlib
import os
import re
import select
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path
from typing import TYPE_CHECKING

from tests.conftest import REPO, wait_until

if TYPE_CHECKING:
    from tests.conftest import Processes

EXAMPLES = REPO / "examples"
STARTED = re.compile(r"^\[INFO\] \[(?P<label>[^\]]+)\]: process started with pid \[(?P<pid>\d+)\]$")
LOG_FOLDER = re.compile(r"^\[INFO\] \[launch\]: All log files can be found below (?P<path>\S+)$")
ANSI = re.compile(r"\x1b\[")
PYTHON = sys.executable


class Output:
    """A child process whose stdout and stderr are read with ``select``, never blocking."""

    def __init__(self, child: subprocess.Popen[str]) -> None:
        self.child = child
        self.pid = child.pid
        assert child.stdout is not None
        assert child.stderr is not None
        self._open = {child.stdout.fileno(): "out", child.stderr.fileno(): "err"}
        self._partial = {"out": b"", "err": b""}
        self._lines: dict[str, list[str]] = {"out": [], "err": []}
        for fd in self._open:
            os.set_blocking(fd, False)

    # --- reading ---------------------------------------------------------------------------

    def _pump(self, timeout: float) -> None:
        if not self._open:
            return
        ready, _, _ = select.select(list(self._open), [], [], max(0.0, timeout))
        for fd in ready:
            try:
                chunk = os.read(fd, 65536)
            except BlockingIOError:
                continue
            name = self._open[fd]
            if not chunk:
                del self._open[fd]
                if self._partial[name]:
                    self._lines[name].append(self._partial[name].decode("utf-8", "replace"))
                    self._partial[name] = b""
                continue
            *lines, self._partial[name] = (self._partial[name] + chunk).split(b"\n")
            self._lines[name].extend(line.decode("utf-8", "replace") for line in lines)

    def lines(self, stream: str = "out") -> list[str]:
        """The complete lines read so far from ``out`` or ``err``."""
        self._pump(0.0)
        return list(self._lines[stream])

    def text(self, stream: str = "out") -> str:
        """Everything read so far from one stream."""
        return "\n".join(self.lines(stream))

    def both(self) -> str:
        """stdout and stderr so far, for assertion messages."""
        return f"--- stdout:\n{self.text('out')}\n--- stderr:\n{self.text('err')}"

    def matching(self, pattern: str, stream: str = "out") -> list[re.Match[str]]:
        """Matches of ``pattern`` (searched in each line) so far."""
        found = (re.search(pattern, line) for line in self.lines(stream))
        return [m for m in found if m is not None]

    def wait_for(
        self, pattern: str, stream: str = "out", timeout: float = 30.0, count: int = 1
    ) -> bool:
        """Wait until ``count`` lines match ``pattern``; False at the deadline or at EOF."""
        deadline = time.monotonic() + timeout
        while True:
            if len(self.matching(pattern, stream)) >= count:
                return True
            left = deadline - time.monotonic()
            if left <= 0 or not self._open:
                return False
            self._pump(min(left, 0.2))

    def finish(self, timeout: float = 30.0) -> int | None:
        """Read to the end and wait for the exit; the exit code, or None at the deadline."""
        deadline = time.monotonic() + timeout
        while self._open and time.monotonic() < deadline:
            self._pump(min(deadline - time.monotonic(), 0.2))
        try:
            return self.child.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            return None

    def interrupt(self, sig: int = signal.SIGINT, timeout: float = 30.0) -> int | None:
        """Send ``sig`` once (by pid) and wait for the exit."""
        if self.child.poll() is None:
            self.child.send_signal(sig)
        return self.finish(timeout)

    # --- what the launcher said ------------------------------------------------------------

    def started(self) -> dict[str, list[int]]:
        """Label → pids, from ``process started with pid [PID]`` lines, in order."""
        found: dict[str, list[int]] = {}
        for line in self.lines("out"):
            match = STARTED.match(line)
            if match:
                found.setdefault(match["label"], []).append(int(match["pid"]))
        return found

    def pids(self) -> list[int]:
        """Every pid the launcher said it started."""
        return [pid for pids in self.started().values() for pid in pids]

    def log_folder(self) -> Path:
        """The folder the launcher writes launch.log into."""
        for line in self.lines("out"):
            match = LOG_FOLDER.match(line)
            if match:
                return Path(match["path"])
        raise AssertionError(f"no log folder line\n{self.both()}")


def running(pid: int, *, allow_unreaped: bool = False) -> bool:
    """Whether ``pid`` is still a live process.

    With ``allow_unreaped``, an exited but unreaped process (a zombie) counts as gone: once its
    launcher is SIGKILLed nobody waits for it (this machine's init does not reap orphans).
    """
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    if not allow_unreaped:
        return True
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


def assert_all_gone(
    pids: list[int], timeout: float = 15.0, *, allow_unreaped: bool = False
) -> None:
    """Every pid must be gone (os.kill(pid, 0) raising ProcessLookupError) within ``timeout``."""
    assert pids, "no launched pids to check"
    wait_until(lambda: not any(running(p, allow_unreaped=allow_unreaped) for p in pids), timeout)
    left = [p for p in pids if running(p, allow_unreaped=allow_unreaped)]
    assert not left, f"processes still running after the launch: {left}"


def kill_leftovers(pids: list[int]) -> None:
    """SIGKILL any pid still alive (teardown safety net after a failed test)."""
    for pid in pids:
        if running(pid, allow_unreaped=True):
            with contextlib.suppress(ProcessLookupError, PermissionError):
                os.kill(pid, signal.SIGKILL)


class Rosl:
    """Runs ``rosl`` commands as real processes on the test's domain, reading them with select."""

    def __init__(self, processes: Processes) -> None:
        self.processes = processes
        self.watched: list[Output] = []

    def start(self, *args: str, env: dict[str, str] | None = None) -> Output:
        """Start ``rosl ARGS...`` and return its output reader."""
        output = Output(self.processes.rosl(*args, env=env))
        self.watched.append(output)
        return output

    def run(self, *args: str, timeout: float = 60.0) -> tuple[int | None, str, str]:
        """Run ``rosl ARGS...`` to the end: (exit code, stdout, stderr)."""
        output = self.start(*args)
        code = output.finish(timeout)
        return code, output.text("out"), output.text("err")

    def close(self) -> None:
        """Kill every launched pid still alive (the processes fixture ends the launchers)."""
        for output in self.watched:
            kill_leftovers(output.pids())


def write_launch(folder: Path, name: str, source: str) -> Path:
    """Write a launch file (``source`` is dedented) and return its path."""
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(source).lstrip("\n"), encoding="utf-8")
    return path


def one_error_line(err: str) -> str:
    """The single stderr line of a failed command (asserting there is exactly one)."""
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, f"expected one error line, got:\n{err}"
    assert "Traceback" not in err
    return lines[0]
