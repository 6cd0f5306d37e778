"""Splitting messages into datagrams and putting them back together.

Every fragment but the last carries exactly ``chunk`` bytes, so a fragment's offset is
``index * len(payload)`` (the last one's is ``total - len(payload)``): fragments may arrive in
any order. Incomplete messages are dropped after ``max_age_ns`` or when a newer message from
the same endpoint starts, and counted. Memory is bounded by one budget for all partial
messages of a reader (``ROSL_REASSEMBLY_MB``, 48 MiB by default), counted as the memory they
really hold: small buffers whole, big ones (lazily mapped) by the pages their fragments
touch, plus :data:`PARTIAL_OVERHEAD` for each one's bookkeeping. When a fragment would pass
the budget the oldest partial messages are evicted (counted); a message bigger than the whole
budget is refused with one warning saying how to raise it. So a flood of fragments from
made-up senders costs at most the budget, and only for a second.
"""

from __future__ import annotations

import mmap
import sys
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rosl.bus.settings import env_number

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.bus.header import Header

MAX_MESSAGE_SIZE = 256 * 1024 * 1024  # bytes; larger claims are foreign or broken
BUDGET_MB = 48  # all partial messages of one reader together (ROSL_REASSEMBLY_MB)
PARTIAL_OVERHEAD = 1024  # bytes charged per partial message for its bookkeeping
PAGE = mmap.PAGESIZE
MAX_AGE_NS = 1_000_000_000


def budget_from_env() -> int:
    """The reassembly budget in bytes (``ROSL_REASSEMBLY_MB``, else the default).

    Raises:
        BusError: ``ROSL_REASSEMBLY_MB`` is not a number of MiB from 1.
    """
    return int(env_number("ROSL_REASSEMBLY_MB", BUDGET_MB, "MiB", least=1.0) * 1024 * 1024)


def split(
    payload: bytes | bytearray | memoryview, chunk: int
) -> Iterator[tuple[int, int, memoryview]]:
    """Yield (index, count, view) for each fragment of ``payload`` (no copies)."""
    view = memoryview(payload)
    total = len(view)
    count = max(1, -(-total // chunk))
    for index in range(count):
        yield index, count, view[index * chunk : (index + 1) * chunk]


# bigger buffers are anonymous mmaps: pages are faulted in as written, and given back to the OS
# the moment the message is delivered or dropped (the heap keeps freed memory: a flood of
# partial messages would leave the process bigger long after it ended)
LAZY_ABOVE = 64 * 1024


def _buffer(size: int) -> bytearray | mmap.mmap:
    # bytearray(n) zero-fills every page up front: for 16 MB that stalls the reader for
    # milliseconds while its socket overflows; an anonymous mmap costs nothing until written
    return mmap.mmap(-1, size) if size > LAZY_ABOVE else bytearray(size)


@dataclass(slots=True)
class _Partial:
    buffer: bytearray | mmap.mmap
    count: int
    started_ns: int
    held: int  # bytes of memory it holds (budgeted)
    received: set[int] = field(default_factory=set)


class Reassembler:
    """Collects fragments into whole messages, keyed by (sender, endpoint, kind, seq)."""

    def __init__(self, max_age_ns: int = MAX_AGE_NS, budget: int | None = None) -> None:
        self.max_age_ns = max_age_ns
        self.budget = budget_from_env() if budget is None else budget
        self.incomplete = 0  # messages dropped with fragments missing
        self.malformed = 0  # fragments that contradict their own header
        self.evicted = 0  # partial messages dropped to stay within the budget
        self.oversize = 0  # fragments of messages bigger than the whole budget
        self._partial: dict[tuple[int, int, int, int], _Partial] = {}
        self._latest: dict[tuple[int, int, int], tuple[int, int, int, int]] = {}
        self._held = 0
        self._warned = False

    @property
    def held(self) -> int:
        """Bytes of memory the partial messages hold."""
        return self._held

    def add(self, header: Header, payload: memoryview, now_ns: int) -> bytearray | mmap.mmap | None:
        """Add one fragment; return the whole payload when this completed it."""
        total, count, index = header.total, header.count, header.index
        size = len(payload)
        last = index == count - 1
        if total > MAX_MESSAGE_SIZE or size > total or (not last and size * count < total):
            self.malformed += 1
            return None
        key = (header.sender, header.endpoint, header.kind, header.seq)
        partial = self._partial.get(key)
        if partial is None:
            if total + PARTIAL_OVERHEAD > self.budget:
                self._too_big(total)
                return None
            try:
                partial = self._start(key, total, count, now_ns)
            except (OSError, MemoryError):  # the OS refused the buffer (e.g. too many maps)
                self.evicted += 1
                return None
        elif partial.count != count or len(partial.buffer) != total:
            self.malformed += 1
            return None
        if index in partial.received:
            return None
        offset = total - size if last else index * size
        if offset < 0 or offset + size > total:
            self.malformed += 1
            return None
        if isinstance(partial.buffer, mmap.mmap):  # lazily mapped: memory grows as it fills
            pages = (offset + size - 1) // PAGE - offset // PAGE + 1 if size else 0
            self._make_room(pages * PAGE, key)  # whole pages: a tiny fragment still takes one
            partial.held += pages * PAGE
            self._held += pages * PAGE
        partial.buffer[offset : offset + size] = payload
        partial.received.add(index)
        if len(partial.received) < count:
            return None
        self._finish(key)
        return partial.buffer

    def _too_big(self, total: int) -> None:
        self.oversize += 1
        if not self._warned:
            self._warned = True
            print(
                f"rosl: warning: dropped a message of {total / 1048576:.1f} MiB: it is bigger "
                f"than the reassembly budget ({self.budget / 1048576:.0f} MiB); raise it with "
                "ROSL_REASSEMBLY_MB",
                file=sys.stderr,
                flush=True,
            )

    def _start(
        self, key: tuple[int, int, int, int], total: int, count: int, now_ns: int
    ) -> _Partial:
        stream = key[:3]
        older = self._latest.get(stream)
        if older is None or 0 < (key[3] - older[3]) & 0xFFFFFFFF < 0x80000000:
            if older is not None and older in self._partial:
                self._drop(older)  # a newer message started: the old one will not complete
            self._latest[stream] = key
        # else an older message's fragment (replayed or late): it must not end the newer one
        buffer = _buffer(total)
        held = PARTIAL_OVERHEAD + (0 if isinstance(buffer, mmap.mmap) else total)
        self._make_room(held, key)
        partial = self._partial[key] = _Partial(buffer, count, now_ns, held)
        self._held += held
        return partial

    def _make_room(self, size: int, keep: tuple[int, int, int, int]) -> None:
        """Evict the oldest partial messages (not ``keep``) until ``size`` more bytes fit."""
        while self._held + size > self.budget:
            oldest = next((k for k in self._partial if k != keep), None)
            if oldest is None:
                return  # only the message being filled is left: it fits (checked at start)
            self._finish(oldest)
            self.evicted += 1

    def _finish(self, key: tuple[int, int, int, int]) -> None:
        partial = self._partial.pop(key)
        self._held -= partial.held
        if self._latest.get(key[:3]) == key:  # nothing of that stream is pending any more
            del self._latest[key[:3]]

    def _drop(self, key: tuple[int, int, int, int]) -> None:
        self._finish(key)
        self.incomplete += 1

    def expire(self, now_ns: int | None = None) -> None:
        """Drop (and count) messages whose fragments stopped arriving."""
        now = time.time_ns() if now_ns is None else now_ns
        for key in [k for k, p in self._partial.items() if now - p.started_ns > self.max_age_ns]:
            self._drop(key)

    @property
    def pending(self) -> int:
        """Messages waiting for fragments."""
        return len(self._partial)
