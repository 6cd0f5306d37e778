"""Splitting messages into datagrams and putting them back together.

Every fragment but the last carries exactly ``chunk`` bytes, so a fragment's offset is
``index * len(payload)`` (the last one's is ``total - len(payload)``): fragments may arrive in
any order. Incomplete messages are dropped after ``max_age_ns`` or when a newer message from
the same endpoint completes, and counted; memory is capped (a burst of garbage headers cannot
make the process allocate without bound).
"""

from __future__ import annotations

import mmap
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.bus.header import Header

MAX_MESSAGE_SIZE = 256 * 1024 * 1024  # bytes; larger claims are foreign or broken
MAX_PENDING_BYTES = 512 * 1024 * 1024  # all partial messages of one process together
MAX_AGE_NS = 1_000_000_000


def split(
    payload: bytes | bytearray | memoryview, chunk: int
) -> Iterator[tuple[int, int, memoryview]]:
    """Yield (index, count, view) for each fragment of ``payload`` (no copies)."""
    view = memoryview(payload)
    total = len(view)
    count = max(1, -(-total // chunk))
    for index in range(count):
        yield index, count, view[index * chunk : (index + 1) * chunk]


LAZY_ABOVE = 1024 * 1024  # bigger buffers are anonymous mmaps: pages are faulted in as written


def _buffer(size: int) -> bytearray | mmap.mmap:
    # bytearray(n) zero-fills every page up front: for 16 MB that stalls the reader for
    # milliseconds while its socket overflows; an anonymous mmap costs nothing until written
    return mmap.mmap(-1, size) if size > LAZY_ABOVE else bytearray(size)


@dataclass(slots=True)
class _Partial:
    buffer: bytearray | mmap.mmap
    count: int
    started_ns: int
    received: set[int] = field(default_factory=set)


class Reassembler:
    """Collects fragments into whole messages, keyed by (sender, endpoint, kind, seq)."""

    def __init__(self, max_age_ns: int = MAX_AGE_NS, max_pending: int = MAX_PENDING_BYTES) -> None:
        self.max_age_ns = max_age_ns
        self.max_pending = max_pending
        self.incomplete = 0  # messages dropped with fragments missing
        self.malformed = 0  # fragments that contradict their own header
        self._partial: dict[tuple[int, int, int, int], _Partial] = {}
        self._latest: dict[tuple[int, int, int], tuple[int, int, int, int]] = {}
        self._pending = 0

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
            self._start(key, total, count, now_ns)
            partial = self._partial[key]
        elif partial.count != count or len(partial.buffer) != total:
            self.malformed += 1
            return None
        if index in partial.received:
            return None
        offset = total - size if last else index * size
        if offset < 0 or offset + size > total:
            self.malformed += 1
            return None
        partial.buffer[offset : offset + size] = payload
        partial.received.add(index)
        if len(partial.received) < count:
            return None
        self._finish(key)
        return partial.buffer

    def _start(self, key: tuple[int, int, int, int], total: int, count: int, now_ns: int) -> None:
        stream = key[:3]
        older = self._latest.get(stream)
        if older is not None and older in self._partial:
            self._drop(older)  # a newer message started: the old one will not complete
        self._latest[stream] = key
        while self._partial and self._pending + total > self.max_pending:
            self._drop(next(iter(self._partial)))
        self._partial[key] = _Partial(_buffer(total), count, now_ns)
        self._pending += total

    def _finish(self, key: tuple[int, int, int, int]) -> None:
        partial = self._partial.pop(key)
        self._pending -= len(partial.buffer)
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
