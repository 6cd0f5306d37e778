"""Helpers for tests that watch real processes on the bus: line readers and observers."""

from __future__ import annotations

import contextlib
import re
import signal
import subprocess
import threading
import time
from typing import TYPE_CHECKING

from tests.conftest import wait_until

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.graph.cache import GraphCache
    from rosl.graph.records import NodeRecord


class Watched:
    """A child process whose stdout and stderr are read line by line, as they come.

    Every wait is bounded. Use :meth:`interrupt` (not ``Processes.stop``) to end it: the
    reader threads own the pipes.
    """

    def __init__(self, child: subprocess.Popen[str]) -> None:
        self.child = child
        self.pid = child.pid
        self.signalled = False
        self._lines: dict[str, list[str]] = {"out": [], "err": []}
        self._changed = threading.Condition()
        self._readers = [
            threading.Thread(target=self._read, args=(name, stream), daemon=True)
            for name, stream in (("out", child.stdout), ("err", child.stderr))
        ]
        for reader in self._readers:
            reader.start()

    def _read(self, name: str, stream: object) -> None:
        with contextlib.suppress(ValueError, OSError):
            for line in iter(stream.readline, ""):  # type: ignore[attr-defined]
                with self._changed:
                    self._lines[name].append(line.rstrip("\n"))
                    self._changed.notify_all()

    def lines(self, stream: str = "out") -> list[str]:
        """Every line read so far from ``out`` or ``err``."""
        with self._changed:
            return list(self._lines[stream])

    def text(self, stream: str = "out") -> str:
        """Everything read so far from one stream."""
        return "\n".join(self.lines(stream))

    def matching(self, pattern: str, stream: str = "out") -> list[re.Match[str]]:
        """Matches of ``pattern`` (searched in each line) so far."""
        found = (re.search(pattern, line) for line in self.lines(stream))
        return [m for m in found if m is not None]

    def wait_for(
        self, pattern: str, stream: str = "out", timeout: float = 30.0, count: int = 1
    ) -> bool:
        """Wait until ``count`` lines match ``pattern`` (or the child ends, or the timeout)."""
        deadline = time.monotonic() + timeout
        with self._changed:
            while True:
                hits = sum(1 for line in self._lines[stream] if re.search(pattern, line))
                if hits >= count:
                    return True
                left = deadline - time.monotonic()
                if left <= 0 or (self.child.poll() is not None and not self._alive()):
                    return False
                self._changed.wait(min(left, 0.1))

    def wait_ready(self, timeout: float = 30.0) -> None:
        """Wait for the child's ``ready`` line; fail with its output if it never comes."""
        if not self.wait_for(r"^ready\b", "out", timeout):
            raise AssertionError(
                f"child {self.pid} never said ready (exit {self.child.poll()})\n"
                f"stdout:\n{self.text('out')}\nstderr:\n{self.text('err')}"
            )

    def _alive(self) -> bool:
        return any(reader.is_alive() for reader in self._readers)

    def tell(self, line: str) -> None:
        """Write a line to the child's stdin (start it with ``stdin=subprocess.PIPE``)."""
        assert self.child.stdin is not None
        self.child.stdin.write(line + "\n")
        self.child.stdin.flush()

    def send(self, sig: int = signal.SIGINT) -> None:
        """Send a signal to the child (by pid), once: a second Ctrl-C means "now"."""
        if self.child.poll() is None:
            self.child.send_signal(sig)
        self.signalled = True

    def interrupt(self, sig: int = signal.SIGINT, timeout: float = 20.0) -> int | None:
        """Ctrl-C the child (unless already signalled) and wait; return the exit code."""
        if not self.signalled:
            self.send(sig)
        try:
            code = self.child.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return None
        for reader in self._readers:
            reader.join(timeout=5)
        return code


def wait_for_node(graph: GraphCache, fqn: str, timeout: float = 30.0) -> NodeRecord:
    """Wait until ``fqn`` is in the graph; return its record."""
    assert graph.wait_for(lambda: bool(graph.find_node(fqn)), timeout), (
        f"{fqn} never showed up; the graph has {[n.fqn for n in graph.nodes()]}"
    )
    return graph.find_node(fqn)[0]


def leaving_time(
    graph: GraphCache, sender: int, act: Callable[[], None], timeout: float
) -> tuple[float, float] | None:
    """Do ``act`` and watch process ``sender`` leave the graph.

    Returns:
        (when it was last heard from, when it was gone), both ``time.monotonic()``; None if it
        was still there after ``timeout``.
    """
    last_seen = 0.0

    def gone() -> bool:
        nonlocal last_seen
        for process in graph.processes():
            if process.sender == sender:
                last_seen = max(last_seen, process.seen)
                return False
        return True

    assert not gone(), "the process was not in the graph to begin with"
    # act right after a fresh announcement from it, so that nearly the whole lease is left:
    # a goodbye then only has to be handled within the lease, however loaded the machine is
    before = last_seen
    wait_until(lambda: gone() or last_seen > before, timeout=10.0, interval=0.005)
    act()
    if not wait_until(gone, timeout=timeout, interval=0.005):
        return None
    return last_seen, time.monotonic()


# --- child programs ---------------------------------------------------------------------------

SPIN_NODES = """
import sys
import rosl

rosl.init([])
names = sys.argv[1:] or ["kid"]
nodes = [rosl.Node(name) for name in names]
print("ready", flush=True)
executor = rosl.get_global_executor()
for node in nodes:
    executor.add_node(node)
executor.spin()
rosl.shutdown()
print("bye", flush=True)
"""  # argv: node names; spins them until Ctrl-C, then shuts down cleanly
