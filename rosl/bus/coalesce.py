"""Opt-in coalescing: many small messages of one writer in one datagram.

Pure Python pays for every ``sendto``/``recv`` (~200 k datagrams/s per core each way), so a
stream of 64-byte messages is limited by syscalls, not bytes. A coalescing writer appends each
small message to a batch — a record of ``seq u32, stamp i64, size u32`` then the bytes — and
sends the batch as one datagram flagged :attr:`~rosl.bus.header.Flags.BATCH` when the next
message would not fit, when a bigger (or addressed) message must keep its place in order, or
at most ``delay_s`` after the batch's first message (a :class:`Flusher` thread, idle while
nothing waits). Readers split a batch back into ordinary deliveries with their own sequence
numbers and stamps, so loss counting, ordering and the recorder see no difference.

Hand-written because it is a few dozen lines on our own header; zenoh does the same with its
64 KB batches. The cost is latency (up to ``delay_s``), hence opt-in.
"""

from __future__ import annotations

import struct
import threading
from bisect import bisect_right
from itertools import accumulate, chain, repeat
from operator import add
from typing import TYPE_CHECKING

from rosl.errors import RoslError

if TYPE_CHECKING:
    from collections.abc import Callable

RECORD = struct.Struct("<IqI")  # seq, stamp (ns), size
DEFAULT_BYTES = 16384  # a batch's payload bound: a few KB keeps the receiver's copies cheap
DEFAULT_DELAY_S = 0.001


class Batch:
    """The pending small messages of one writer."""

    def __init__(
        self, send: Callable[[int, int, bytes | bytearray], None], limit: int, flusher: Flusher
    ) -> None:
        self.limit = limit
        self._send = send  # (first seq, first stamp, records) -> one datagram
        self._flusher = flusher
        self._lock = threading.Lock()
        self._records = bytearray()  # the first record's seq and stamp head the datagram

    def fits(self, size: int) -> bool:
        """Whether a message of ``size`` bytes is small enough to be batched."""
        return RECORD.size + size <= self.limit

    def add(self, seq: int, stamp: int, payload: bytes | bytearray | memoryview) -> None:
        """Append one message (sending the batch first when it would not fit)."""
        with self._lock:
            if len(self._records) + RECORD.size + len(payload) > self.limit:
                self._flush_locked()
            timed = bool(self._records) or self._flusher.due(self)
            self._records += RECORD.pack(seq, stamp, len(payload))
            self._records += payload
            if not timed:  # the flusher has closed: nothing would send it later
                self._flush_locked()

    def add_all(
        self, first_seq: int, stamp: int, payloads: list[bytes], flush: bool = False
    ) -> None:
        """Append messages numbered ``first_seq`` on, in order, each small enough to fit.

        What :meth:`add` does for each, in one loop under one lock; with ``flush``, then what
        :meth:`flush` does, under the same lock.
        """
        pack, size, limit = RECORD.pack, RECORD.size, self.limit
        count = len(payloads)
        sizes = list(map(len, payloads))
        with self._lock:
            if first_seq + count <= 0x100000000:  # no number wraps: runs framed with no loop
                self._add_runs(first_seq, stamp, payloads, sizes, flush)
                return
            timed = bool(self._records) or self._flusher.due(self)
            for offset, payload in enumerate(payloads):
                if len(self._records) + size + len(payload) > limit:
                    self._flush_locked()
                    timed = self._flusher.due(self)
                records = self._records
                records += pack((first_seq + offset) & 0xFFFFFFFF, stamp, len(payload))
                records += payload
            if flush or not timed:  # asked, or the flusher has closed: nothing would send it
                self._flush_locked()

    def _add_runs(
        self, first_seq: int, stamp: int, payloads: list[bytes], sizes: list[int], flush: bool
    ) -> None:
        """:meth:`add_all`'s records, in runs that each fill what the batch has room for.

        The same batches as one :meth:`add` each (a batch is sent when the next record would
        not fit), but each run's record heads are packed by ``map`` and joined with the
        messages in one call. A full batch of a run alone goes as it is, with no copy.
        """
        size, limit = RECORD.size, self.limit
        count = len(payloads)
        total = size * count + sum(sizes)
        ends: list[int] = []  # framed bytes up to each record (when they do not all fit)
        start = done = 0  # the first record of the next run, the framed bytes before it
        timed = bool(self._records)  # the flusher knows of what waits (told when it begins)
        while start < count:
            if len(self._records) + total - done <= limit:  # the rest fits (the usual case)
                end = count
            else:
                ends = ends or list(accumulate(map(add, sizes, repeat(size))))
                end = bisect_right(ends, done + limit - len(self._records), start)
                if end == start and self._records:  # the next does not fit beside what waits
                    self._flush_locked()
                    timed = False
                    continue
                end = max(end, start + 1)  # (one too big for any batch still goes, alone)
            whole = start == 0 and end == count
            run_sizes = sizes if whole else sizes[start:end]
            run = payloads if whole else payloads[start:end]
            heads = map(RECORD.pack, range(first_seq + start, first_seq + end), repeat(stamp),
                        run_sizes)  # fmt: skip
            joined = b"".join(chain.from_iterable(zip(heads, run, strict=True)))
            if not self._records and (end < count or flush):  # full, or asked: it goes now
                self._send(first_seq + start, stamp, joined)
            else:
                timed = timed or self._flusher.due(self)
                self._records += joined
                if end < count:  # full: the next run starts a new batch
                    self._flush_locked()
                    timed = False
            start, done = end, (ends[end - 1] if ends else total)
        if self._records and (flush or not timed):  # asked, or the flusher has closed
            self._flush_locked()

    def flush(self) -> None:
        """Send what is pending now."""
        with self._lock:
            self._flush_locked()

    def _flush_locked(self) -> None:
        if not self._records:
            return
        seq, stamp, _ = RECORD.unpack_from(self._records)
        records, self._records = self._records, bytearray()  # handed over: never changed again
        self._send(seq, stamp, records)


def split_records(payload: memoryview) -> list[tuple[int, int, memoryview]]:
    """(seq, stamp, bytes) of each message in a batch; raises ValueError when malformed."""
    out = []
    offset, end = 0, len(payload)
    unpack = RECORD.unpack_from
    while offset < end:
        if end - offset < RECORD.size:
            raise ValueError("truncated batch record")
        seq, stamp, size = unpack(payload, offset)
        offset += RECORD.size
        if size > end - offset:
            raise ValueError("batch record longer than the datagram")
        out.append((seq, stamp, payload[offset : offset + size]))
        offset += size
    return out


class Flusher:
    """Sends every batch at most ``delay_s`` after its first message (one thread, lazily)."""

    def __init__(self, delay_s: float = DEFAULT_DELAY_S) -> None:
        self.delay_s = delay_s
        self._due: list[Batch] = []
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self.failed = 0  # batches the bus refused to send

    def due(self, batch: Batch) -> bool:
        """Note that ``batch`` has a first message waiting; False once closed (send it now)."""
        with self._lock:
            if self._stop.is_set():
                return False
            self._due.append(batch)
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="rosl-coalesce", daemon=True)
                self._thread.start()
        self._wake.set()
        return True

    def flush(self) -> None:
        """Send every pending batch now (a batch the network refused is counted, not kept)."""
        with self._lock:
            batches, self._due = self._due, []
        for batch in batches:
            try:
                batch.flush()
            except RoslError:  # the bus could not send: the writer's next send will say so
                self.failed += 1

    def close(self) -> None:
        """Send what is pending and stop the thread; later batches go out at once."""
        with self._lock:
            self._stop.set()
        self.flush()
        self._wake.set()
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=1.0)

    def _run(self) -> None:
        while not self._stop.is_set():
            self._wake.wait()
            self._wake.clear()
            if self._stop.wait(self.delay_s):
                return
            self.flush()
