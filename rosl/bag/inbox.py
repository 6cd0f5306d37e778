"""Where received messages wait before the recorder writes them.

Two waits, both bounded in bytes: :class:`Intake`, a thread that drains the socket while the
recorder writes, so that a burst faster than the disk waits in memory instead of overflowing
the socket's buffer in the kernel; and :class:`Pending`, the hold of messages whose topic
cannot be named yet (or whose schema is still being read).
"""

from __future__ import annotations

import mmap
import threading
import time
from collections import deque
from typing import TYPE_CHECKING, NamedTuple

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.wire import Delivery
    from rosl.node.participant import Participant

HELD_OVERHEAD = 512  # bytes per held message besides its buffer: tuple, view, bookkeeping
INBOX_BYTES = 256 * 1024 * 1024  # received, not yet written: a burst waits here


class Intake:
    """A thread that receives for the recorder and queues what came, bounded in bytes."""

    def __init__(self, participant: Participant) -> None:
        self._participant = participant
        self._queue: deque[Delivery] = deque()
        self._bytes = 0
        self._lock = threading.Lock()
        self._arrived = threading.Event()
        self._stopping = False
        self._failure: BaseException | None = None  # what ended the thread: take() raises it
        self._thread = threading.Thread(target=self._run, name="rosl-recorder-intake", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        try:
            while not self._stopping and not self._participant.closed:
                if self._bytes > INBOX_BYTES:  # the writer is far behind: let the socket fill
                    self._arrived.set()
                    time.sleep(0.01)
                    continue
                self._participant.poll(0.05, sink=self._put)
        except BaseException as err:  # told to the recording thread, not lost with this one
            self._failure = err
            self._arrived.set()

    def _put(self, delivery: Delivery) -> None:
        with self._lock:
            self._queue.append(delivery)
            self._bytes += len(delivery.payload) + HELD_OVERHEAD
        self._arrived.set()

    @property
    def queued(self) -> int:
        """How many deliveries wait to be taken."""
        return len(self._queue)

    def wait(self, timeout: float) -> None:
        """Wait (at most ``timeout``) until something is queued."""
        if not self._queue:
            self._arrived.wait(timeout)

    def take(self) -> list[Delivery]:
        """Everything queued so far, oldest first.

        Raises:
            BaseException: what ended the receiving thread (once what came before is taken).
        """
        if self._failure is not None and not self._queue:
            raise self._failure
        with self._lock:
            taken = list(self._queue)
            self._queue.clear()
            self._bytes = 0
            self._arrived.clear()
        return taken

    def stop(self) -> None:
        """Stop receiving and wait for the thread (what is queued stays for :meth:`take`)."""
        self._stopping = True
        self._thread.join()  # it polls in steps of 50 ms: this ends


class Held(NamedTuple):
    """One held message, with its topic key and the buffer its payload keeps alive."""

    delivery: Delivery
    key: tuple[int, int]  # (topic hash, type hash)
    buffer: int  # id() of the buffer its payload keeps alive (alive while held: unique)


class Pending:
    """Messages held until their topic (or its schema) is known, oldest first, bounded.

    A held payload is a view of the datagram it came in (or of a reassembled buffer) and keeps
    that whole buffer alive, so the byte bound counts each buffer once, whole, however many held
    messages share it (the messages of a coalesced datagram), plus ``HELD_OVERHEAD`` per
    message. Counting only each message's own bytes would let a sender keep one small message of
    each of many large batches (its stamps decide which are evicted first) and hold far more.

    When a new message does not fit, the oldest held messages are dropped first, whatever their
    topic. A topic about to be announced has its messages among the newest: they survive a
    flood of strangers' topics unless the flood alone outgrows the bound in the moment before
    the announcement, and nothing can keep them then. The other choices are worse: refusing
    new messages when full lets a flood that came first shut out the real topic until its
    entries age out; a per-topic share does not help, because a flood of random names gives
    every stranger a topic of its own while the real topic, with its several messages, is the
    biggest holder and would lose first.
    """

    def __init__(self, max_count: int, max_bytes: int) -> None:
        self.max_count = max_count
        self.max_bytes = max_bytes
        self.held: deque[Held] = deque()
        self.since: dict[tuple[int, int], float] = {}  # only keys with messages held
        self.counts: dict[tuple[int, int], int] = {}
        self.buffers: dict[int, list[int]] = {}  # id -> [messages holding it, its size]
        self.bytes = 0  # the buffers counted once each, plus the overhead per message

    def __len__(self) -> int:
        return len(self.held)

    def add(self, delivery: Delivery, now: float) -> int:
        """Hold a message; return how many messages were dropped to bound the hold."""
        buffer, size = retained(delivery.payload)
        if HELD_OVERHEAD + size > self.max_bytes:  # bigger than the whole hold
            return 1
        ident = id(buffer)
        dropped = 0
        while self.held and (
            len(self.held) >= self.max_count
            or self.bytes + HELD_OVERHEAD + (0 if ident in self.buffers else size) > self.max_bytes
        ):
            self._release(self.held.popleft())
            dropped += 1
        key = (delivery.topic, delivery.type)
        self.held.append(Held(delivery, key, ident))
        self.since.setdefault(key, now)
        self.counts[key] = self.counts.get(key, 0) + 1
        holders = self.buffers.get(ident)
        if holders is None:
            self.buffers[ident] = [1, size]
            self.bytes += size
        else:
            holders[0] += 1
        self.bytes += HELD_OVERHEAD
        return dropped

    def retry(self, take: Callable[[Delivery], bool]) -> None:
        """Give every held message to ``take`` in order; keep those it refuses, in order."""
        for _ in range(len(self.held)):
            entry = self.held[0]
            if take(entry.delivery):
                self._release(self.held.popleft())
            else:
                self.held.rotate(-1)

    def expire(self, now: float, limit: float) -> int:
        """Drop the messages of topics held for more than ``limit`` seconds; return how many."""
        old = {key for key, since in self.since.items() if now - since > limit}
        if not old:
            return 0
        kept: deque[Held] = deque()
        for entry in self.held:
            if entry.key in old:
                self._release(entry)
            else:
                kept.append(entry)
        dropped = len(self.held) - len(kept)
        self.held = kept
        return dropped

    def _release(self, entry: Held) -> None:
        left = self.counts[entry.key] - 1
        if left:
            self.counts[entry.key] = left
        else:
            del self.counts[entry.key]
            del self.since[entry.key]
        holders = self.buffers[entry.buffer]
        holders[0] -= 1
        self.bytes -= HELD_OVERHEAD
        if not holders[0]:
            del self.buffers[entry.buffer]
            self.bytes -= holders[1]


def retained(payload: memoryview | bytearray | mmap.mmap) -> tuple[object, int]:
    """The buffer a payload keeps alive, and its size in bytes."""
    if not isinstance(payload, memoryview):
        return payload, len(payload)
    base = payload.obj
    if isinstance(base, (bytes, bytearray, mmap.mmap)):
        return base, len(base)
    return (payload if base is None else base), payload.nbytes  # at least the view itself
