"""Helpers for the node tests: children whose output is read with deadlines, bounded spinning."""

from __future__ import annotations

import contextlib
import re
import subprocess
import textwrap
import time
from typing import TYPE_CHECKING, Any

from tests.conftest import ChildOutput

if TYPE_CHECKING:
    from collections.abc import Callable

    from tests.conftest import Processes

STREAMS = ("out", "err")


class Child(ChildOutput):
    """A child process whose stdout/stderr are read without blocking, always with a deadline."""

    def __init__(self, popen: subprocess.Popen[str], processes: Processes) -> None:
        super().__init__(popen)
        self._processes = processes
        self._pos = {s: 0 for s in STREAMS}
        self.stopped = False
        self.stopped_by_us = False  # finish() had to stop it

    # --- reading ---------------------------------------------------------------------------

    def wait_for(self, pattern: str, *, stream: str = "out", timeout: float = 30.0) -> Any:
        """The next match of ``pattern`` (multiline regex) after the last one, or None."""
        regex = re.compile(pattern, re.MULTILINE)
        deadline = time.monotonic() + timeout
        last_look = False
        while True:
            match = regex.search(self.text[stream], self._pos[stream])
            if match:
                self._pos[stream] = match.end()
                return match
            if last_look or (not self._open and self.popen.poll() is not None):
                return None
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                last_look = True  # one more read of what is already there, then give up
            self._read(max(0.0, min(remaining, 0.05)))

    def expect(self, pattern: str, *, stream: str = "out", timeout: float = 30.0) -> Any:
        """Like :meth:`wait_for` but fail the test with the child's output when missing."""
        match = self.wait_for(pattern, stream=stream, timeout=timeout)
        if match is None:
            self.pump()
            raise AssertionError(
                f"child never printed {pattern!r} on std{stream} within {timeout} s "
                f"(exit code {self.popen.poll()})\n--- stdout ---\n{self.text['out']}"
                f"\n--- stderr ---\n{self.text['err']}"
            )
        return match

    def count(self, pattern: str, *, stream: str = "out") -> int:
        """How many times ``pattern`` occurs in everything read so far."""
        self.pump()
        return len(re.findall(pattern, self.text[stream], re.MULTILINE))

    # --- ending ----------------------------------------------------------------------------

    def finish(self, timeout: float = 30.0) -> tuple[str, str]:
        """Wait (bounded) for the child to exit on its own; Ctrl-C it if it does not."""
        deadline = time.monotonic() + timeout
        while self._open and (remaining := deadline - time.monotonic()) > 0:
            self._read(min(remaining, 0.05))
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.popen.wait(timeout=max(0.1, deadline - time.monotonic()))
        self.stopped_by_us = self.popen.poll() is None  # it had to be Ctrl-C'd (or killed)
        return self.stop()

    def stop(self, timeout: float = 5.0) -> tuple[str, str]:
        """Ctrl-C the child (SIGKILL after ``timeout``); return all of its stdout and stderr."""
        if not self.stopped:
            self.stopped = True
            out, err = self._processes.stop(self.popen, timeout=timeout)
            self.text["out"] += out or ""
            self.text["err"] += err or ""
        return self.text["out"], self.text["err"]

    @property
    def returncode(self) -> int | None:
        return self.popen.returncode


def snippet(code: str) -> str:
    """Dedent a child's source."""
    return textwrap.dedent(code).lstrip()


def spin_until(
    node: Any,
    predicate: Callable[[], bool],
    timeout: float = 5.0,
    *,
    each: Callable[[], Any] | None = None,
    every: float = 0.1,
) -> bool:
    """Spin ``node`` on this thread until ``predicate()`` or the deadline.

    ``each`` is called at most every ``every`` seconds while waiting (e.g. to publish again).
    """
    import rosl

    deadline = time.monotonic() + timeout
    last_each = -1e9
    while not predicate():
        now = time.monotonic()
        if now >= deadline:
            return predicate()
        if each is not None and now - last_each >= every:
            last_each = now
            each()
        rosl.spin_once(node, timeout_sec=0.02)
    return True


def spin_for(node: Any, seconds: float) -> None:
    """Spin ``node`` on this thread for ``seconds``."""
    import rosl

    deadline = time.monotonic() + seconds
    while (remaining := deadline - time.monotonic()) > 0:
        rosl.spin_once(node, timeout_sec=min(remaining, 0.02))
