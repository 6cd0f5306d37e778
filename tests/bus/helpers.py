"""Helpers for the bus tests: a second locked domain, a socket collector, child output lines."""

from __future__ import annotations

import contextlib
import fcntl
import queue
import random
import select
import threading
import time
from typing import TYPE_CHECKING

from rosl.bus.header import topic_hash
from rosl.bus.transport import channel_of
from tests.conftest import LOCK_DIR

if TYPE_CHECKING:
    import socket
    import subprocess
    from collections.abc import Callable, Iterator

    from rosl.bus.wire import Delivery, Reader


def same_channel_name(name: str, prefix: str | None = None) -> str:
    """Another topic name (``prefix`` + a number) whose hash lands on ``name``'s channel."""
    channel = channel_of(topic_hash(name))
    for i in range(10_000):
        other = f"{name}_other{i}" if prefix is None else f"{prefix}{i}"
        if channel_of(topic_hash(other)) == channel:
            return other
    raise AssertionError("no topic name on the same channel")


@contextlib.contextmanager
def another_domain(*exclude: int) -> Iterator[int]:
    """Lock one more domain id the way the ``domain_id`` fixture does (for isolation tests)."""
    LOCK_DIR.mkdir(exist_ok=True)
    candidates = [d for d in range(20, 233) if d not in exclude]
    random.shuffle(candidates)
    for domain in candidates:
        handle = open(LOCK_DIR / f"{domain}.lock", "w")  # noqa: SIM115 - held while in use
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        try:
            yield domain
        finally:
            handle.close()
        return
    raise RuntimeError("no second free test domain id")


class Collector:
    """Drains one socket with a Reader on a background thread into ``deliveries``."""

    def __init__(self, reader: Reader, sock: socket.socket) -> None:
        self.reader = reader
        self.sock = sock
        self.deliveries: list[Delivery] = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        batch: list[Delivery] = []
        while not self._stop.is_set():
            ready, _, _ = select.select([self.sock], [], [], 0.02)
            if not ready:
                continue
            while self.reader.drain(self.sock.recv, batch):
                pass
            with self._lock:
                self.deliveries.extend(batch)
            batch.clear()

    def snapshot(self) -> list[Delivery]:
        with self._lock:
            return list(self.deliveries)

    def wait_for(self, predicate: Callable[[list[Delivery]], bool], timeout: float = 5.0) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if predicate(self.snapshot()):
                return True
            time.sleep(0.01)
        return predicate(self.snapshot())

    def wait_count(self, count: int, timeout: float = 5.0) -> list[Delivery]:
        self.wait_for(lambda got: len(got) >= count, timeout)
        return self.snapshot()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2.0)


class Lines:
    """Reads a child's stdout (or stderr) line by line on a thread; waits are bounded."""

    def __init__(self, stream: object) -> None:
        self.lines: list[str] = []
        self._queue: queue.Queue[str | None] = queue.Queue()
        self._thread = threading.Thread(target=self._run, args=(stream,), daemon=True)
        self._thread.start()
        self.closed = False

    def _run(self, stream: object) -> None:
        try:
            for line in stream:  # type: ignore[attr-defined]
                self._queue.put(line.rstrip("\n"))
        except (ValueError, OSError):
            pass  # closed by the processes fixture while we were reading
        self._queue.put(None)

    def _pull(self, timeout: float) -> bool:
        try:
            line = self._queue.get(timeout=max(0.0, timeout))
        except queue.Empty:
            return False
        if line is None:
            self.closed = True
            return False
        self.lines.append(line)
        return True

    def wait_for(self, predicate: Callable[[list[str]], bool], timeout: float) -> bool:
        """Wait until ``predicate(lines so far)`` holds, the stream ends, or the timeout."""
        deadline = time.monotonic() + timeout
        while not predicate(self.lines):
            if self.closed:
                return False
            if not self._pull(deadline - time.monotonic()) and time.monotonic() >= deadline:
                return predicate(self.lines)
        return True

    def wait_line(self, prefix: str, timeout: float) -> str | None:
        """The first line starting with ``prefix`` (waiting for it up to ``timeout``)."""
        if self.wait_for(lambda lines: any(x.startswith(prefix) for x in lines), timeout):
            return next(x for x in self.lines if x.startswith(prefix))
        return None

    def rest(self, timeout: float = 5.0) -> list[str]:
        """Every line, after waiting (bounded) for the stream to end."""
        self.wait_for(lambda _: False, timeout)
        return self.lines


def wait_exit(child: subprocess.Popen[str], timeout: float) -> int | None:
    """The child's exit code, or None if it is still running after ``timeout``."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        code = child.poll()
        if code is not None:
            return code
        time.sleep(0.02)
    return child.poll()


# --- node snippets shared by the process tests ------------------------------------------------

TALKER = r"""
import sys
import rosl
from std_msgs.msg import String

rosl.init()
node = rosl.Node(sys.argv[1])
pub = node.create_publisher(String, sys.argv[2], 10)
count = 0

def tick():
    global count
    count += 1
    pub.publish(String(data=f"hello {count}"))

node.create_timer(0.01, tick)
print("up", flush=True)
rosl.spin(node)
print("sent", count, flush=True)
rosl.shutdown()
"""

LISTENER = r"""
import sys
import rosl
from std_msgs.msg import String

rosl.init()
node = rosl.Node(sys.argv[1])
good = bad = 0

def on_message(msg):
    global good, bad
    if msg.data.startswith("hello "):
        good += 1
        if good % 10 == 0:
            print("good", good, flush=True)
    else:
        bad += 1

sub = node.create_subscription(String, sys.argv[2], on_message, 10)
print("up", flush=True)
rosl.spin(node)
reader = node.participant.reader
print("final", good, bad, flush=True)
print("stats", f"received={sub.received} mismatched={sub.mismatched}",
      f"undecodable={sub.undecodable} bus={reader.received()} lost={reader.lost()}",
      f"foreign={reader.foreign} unwanted={reader.unwanted}",
      f"malformed={reader.reassembler.malformed}", flush=True)
rosl.shutdown()
"""

PROBE = r"""
import sys
import rosl

rosl.init()
node = rosl.Node("bus_probe")
graph = node.participant.graph
want = set(sys.argv[1:])
found = graph.wait_for(lambda: want <= {n.fqn for n in graph.nodes()}, 15.0)
print("nodes", " ".join(sorted(n.fqn for n in graph.nodes())), flush=True)
print("found" if found else "missing", flush=True)
rosl.shutdown()
"""


def good_count(lines: list[str]) -> int:
    """The listener's latest count of valid messages (it prints one line every 10)."""
    return max((int(x.split()[1]) for x in lines if x.startswith("good ")), default=0)


def signed(datagram: bytes, domain: int) -> bytes:
    """``datagram`` as a process holding the domain's key sends it: SIGNED set, MAC appended.

    A datagram that already carries a MAC loses it first, so mutated real datagrams are
    re-signed (what a fuzzer with the key sends, reaching every parser behind the MAC check).
    """
    from rosl.bus import auth
    from rosl.bus.header import HEADER_SIZE, Flags

    key = auth.load(domain)
    assert key is not None, "the tests run with the default per-user key"
    body = bytearray(datagram)
    if len(body) >= HEADER_SIZE:
        if body[4] & Flags.SIGNED:
            del body[-auth.MAC_SIZE :]
        body[4] |= Flags.SIGNED
    return bytes(body) + key.mac(bytes(body))


def unsigned_payload(datagram: bytes) -> bytes:
    """The payload of a real (signed) datagram: between the header and the MAC."""
    from rosl.bus.auth import MAC_SIZE
    from rosl.bus.header import HEADER_SIZE, Flags

    end = len(datagram) - (MAC_SIZE if datagram[4] & Flags.SIGNED else 0)
    return datagram[HEADER_SIZE:end]
