"""The shared-memory ring of one publisher: its file layout, the writer, and the reader's maps.

A large message is written into a slot of its publisher's ring (a file in ``/dev/shm``, mode
0600) and the bus carries only a :data:`DESCRIPTOR` (pid, ring incarnation, message number,
length) in a normal signed datagram. Subscribers of this host map the ring read-only and copy
the message out. Policy (when to use a ring, names, cleanup) lives in :mod:`rosl.bus.shm`.

Layout: the file starts with the :data:`HEADER` (magic, slots, slot capacity, owner pid, the
owner's process start time and pid namespace, which the cleanup pass checks) and from byte 64
one 8-byte *generation* per slot, in as many pages as they take (one page up to 504 slots),
then a page of reader entries (:func:`readers_at`); slot ``i``'s bytes start after that, at
``data_at(slots) + i * capacity``.

Safety against a slow subscriber (a seqlock per slot): the writer of message ``n`` sets the
slot's generation to ``2n - 1`` (odd: being written), copies the payload, then sets it to
``2n``. A reader of message ``n`` checks the generation is ``2n``, copies the bytes out, and
checks it again; any other value means the slot was (or is being) reused for a newer message:
the read is refused and counted (``overwritten``), never delivered torn. A reader that finds
the writer within a sixteenth of the ring (a slot at least) of reusing the slot it is about
to copy does not copy (the copy would likely end torn, and at that distance its source has
left the CPU's caches): it drops that many messages, counted the same way, and goes on with
the next; skipping further, to the newest messages, measured no faster for a reader that
stays behind, and lost more to a passing stall. The checks rely on stores becoming visible
in program order, as on x86-64; the slot is only reused after a whole ring of newer
messages, which bounds the window on weaker CPUs to that lap.

Reliable readers hold the writer back, briefly (as a DDS reliable writer blocks for its
readers, up to ``max_blocking_time``): a reader of a reliable subscription takes an entry in
the readers' page (under ``flock``, so two readers never take one) and writes into it the
number of the last message it is done with and when. A reliable writer about to begin a
message that would push such a reader into dropping waits (sleeping 50 µs, then longer, up
to 400 µs) while that reader read something in the last :data:`HOLD_NS`, for
:data:`MAX_WAIT_NS` at most; then it writes on, and the reader loses what it did not read,
counted as before. So a burst, or the page faults of a new ring's first lap, slows the
publisher instead of costing messages, while a subscriber busy elsewhere (a long callback, a
crash, an exit) costs it at most :data:`HOLD_NS` once. Each reader has a credit of waiting,
:data:`BUDGET_NS`, refilled at that much per :data:`WINDOW_NS`: one that spends it is
steadily slower than the writer (a keep-last subscriber whose callbacks cannot keep up), not
behind by a burst, and is not waited for until it has caught up; so it costs the publisher a
quarter of its time, and a credit, at most, and sets its pace only if it is at most a third
slower (Fast DDS's data sharing, which waits for every reader, lets any reader set it).
Best-effort publishers and subscribers never wait and never hold.

Zero-copy: a view into a slot would be safe only until the slot is reused, which a reader
cannot prevent; so every read makes exactly one copy and the sequence check runs after that
copy. The copy goes into a buffer of the reader's pool that nothing refers to any more
(fresh memory costs more page faults than the copy) and is handed out as a read-only view:
``np.frombuffer`` wraps it without a copy, the recorder writes it as it is, and the buffer is
used again only once no delivery, array or view holds it. (Decoded messages still give each
subscription its own writable arrays, as rclpy does: that copy is the deserializer's policy,
so two subscriptions of one process never share an array.)

Hand-written because no library does this: ``multiprocessing.shared_memory`` gives a
segment but no ring, no torn-read check, and its resource tracker unlinks segments other
processes still use; iceoryx2, eCAL and dora ship their own rings behind their own
transports, not a slot store next to ours.
"""

from __future__ import annotations

import contextlib
import fcntl
import mmap
import os
import stat
import struct
import sys
import time
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.transport import Buffer

    # (sender, endpoint, pid, incarnation) -> the ring's path (see shm.py)
    Namer = Callable[[int, int, int, int], str]

MAGIC = b"RLSHM\x00\x03\x00"  # layout 3: a page of reader entries before the slots
HEADER = struct.Struct("<8sIIIIQQ")  # magic, slots, capacity, pid, -, start time, pid ns
GENERATIONS_AT = 64
PAGE = mmap.PAGESIZE
MAX_SLOTS = 4096  # slots one ring may have (its generations then take 9 pages)
DESCRIPTOR = struct.Struct("<IIQI")  # pid, incarnation, message number, length
# the readers' page: a count of its changes (4 u64, the first used), then one entry of 4 u64
# per reader: its token (pid and a number; 0: a free entry), cursor (the last message it is
# done with), stamp (CLOCK_MONOTONIC ns of its last read) and flags
ENTRIES = PAGE // 32
FIRST_ENTRY = 4
HOLD = 1  # an entry's flag: the reader is reliable (its writer waits for it, see below)
HOLD_NS = 10_000_000  # a reader that read nothing for this long is not waited for
MAX_WAIT_NS = 100_000_000  # one message waits at most this long (DDS's max_blocking_time)
# a reader's credit of waiting, refilled at BUDGET_NS per WINDOW_NS: one that spends it is
# steadily slower than the writer, not behind by a burst, and is not waited for until it
# caught up
WINDOW_NS, BUDGET_NS = 100_000_000, 25_000_000
PAUSES = (50e-6, 100e-6, 200e-6, 400e-6)  # a waiting writer's sleeps, then the last again
CLAIM_RETRY_NS = 1_000_000_000  # a reader that found no free entry looks again this late
CLAIM_STALE_NS = 10_000_000_000  # an entry untouched this long is free for another reader
MAX_MAPS = 64  # rings a reader keeps mapped at once (least recently used go first)
POOLED = 8  # buffers kept per ring size beyond those one drain's copies take
DRAIN_BYTES = 1024 * 1024  # copies one drain of a receiver makes at most (see wire.py)
_UNUSED = 3  # sys.getrefcount of a pooled buffer nobody holds: the pool, the loop, the call


def _token() -> int:
    """Who takes a ring's entry: this pid, and 32 random bits (other pid namespaces' pids)."""
    return os.getpid() << 32 | int.from_bytes(os.urandom(4), "little") | 1


def _round_up(value: int, step: int) -> int:
    return -(-value // step) * step


def readers_at(slots: int) -> int:
    """Where the readers' page of a ring of ``slots`` slots starts: after the generations."""
    return _round_up(GENERATIONS_AT + 8 * slots, PAGE)


def data_at(slots: int) -> int:
    """Where slot 0 starts in a ring of ``slots`` slots: after the readers' page."""
    return readers_at(slots) + PAGE


def segment_size(slots: int, capacity: int) -> int:
    """Bytes of a ring file of ``slots`` slots of ``capacity`` bytes."""
    return data_at(slots) + slots * capacity


@dataclass(frozen=True, slots=True)
class Owner:
    """Who made a ring: checked by the cleanup pass (a pid alone can be reused)."""

    pid: int
    start_time: int  # field 22 of /proc/<pid>/stat (clock ticks since boot)
    pid_ns: int  # inode of /proc/<pid>/ns/pid: pids of another namespace are not ours


def read_owner(path: str) -> Owner | None:
    """The owner a ring file names in its header (None: not a ring, or unreadable)."""
    try:
        with open(path, "rb") as handle:
            head = handle.read(HEADER.size)
    except OSError:
        return None
    if len(head) < HEADER.size:
        return None
    magic, _slots, _capacity, pid, _, start, pid_ns = HEADER.unpack(head)
    return Owner(pid, start, pid_ns) if magic == MAGIC else None


class RingWriter:
    """One publisher's ring: writes messages into slots, returns their descriptors."""

    def __init__(
        self, path: str, owner: Owner, incarnation: int, slots: int, capacity: int
    ) -> None:
        """Create the file (mode 0600, never an existing one) and reserve its memory.

        Raises:
            OSError: the file exists, or /dev/shm has no room (posix_fallocate says so up
                front, instead of a SIGBUS on the first write).
        """
        self.path = path
        self.incarnation = incarnation
        self.slots = max(1, min(slots, MAX_SLOTS))
        self.capacity = _round_up(capacity, PAGE)
        self._data_at = data_at(self.slots)
        self._pid = owner.pid
        size = segment_size(self.slots, self.capacity)
        flags = os.O_RDWR | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC
        fd = os.open(path, flags, 0o600)
        try:
            os.fchmod(fd, 0o600)  # the umask may only remove bits; make sure of the rest
            os.posix_fallocate(fd, 0, size)
            self._map = mmap.mmap(fd, size, mmap.MAP_SHARED, mmap.PROT_READ | mmap.PROT_WRITE)
        except OSError:
            os.close(fd)
            with contextlib.suppress(OSError):
                os.unlink(path)
            raise
        os.close(fd)
        header = HEADER.pack(
            MAGIC, self.slots, self.capacity, owner.pid, 0, owner.start_time, owner.pid_ns
        )
        self._map[: HEADER.size] = header
        self._view = memoryview(self._map)
        self._generations = self._view[GENERATIONS_AT : GENERATIONS_AT + 8 * self.slots].cast("Q")
        at = readers_at(self.slots)
        self._entries = self._view[at : at + PAGE].cast("Q")
        self._margin = max(1, self.slots // 16)  # (as the reader's, see _Mapped)
        self._held: list[int] = []  # entries of reliable readers (first words' indexes)
        self._changes = 0  # the readers' page's count of changes when _held was looked up
        self._next = 1
        self.hold_ns = HOLD_NS  # (tests lengthen these: a loaded machine's stalls)
        self.max_wait_ns = MAX_WAIT_NS
        self.budget_ns = BUDGET_NS
        self._credit: dict[int, list[int]] = {}  # entry -> [ns it may still cost, as of when]
        self._excused: set[int] = set()  # entries that spent their budget, until they caught up
        self._tokens: dict[int, int] = {}  # entry -> the token of the reader it was charged to
        self.waited = 0  # messages that waited for a reliable reader
        self.waited_out = 0  # ... until MAX_WAIT_NS, then overwrote what it had not read
        self.excused = 0  # times a reader spent its budget (then it lost messages, counted)
        self.waited_ns = 0  # time spent waiting, in all
        self.closed = False

    def make_room(self) -> None:
        """Wait, bounded, for reliable readers the next message would push into dropping.

        A reliable publisher's, before :meth:`put` (see the module docstring); it only reads
        the ring, so it needs no lock (a ring closed meanwhile ends the wait).
        """
        if self.closed:
            return
        entries = self._entries
        if entries[0] != self._changes:  # a reader came or went
            self._holders()
        if self._held:
            need = self._next - self.slots + self._margin  # a reader's cursor must be this far
            excused = self._excused
            for index in self._held:
                if entries[index + 1] < need:
                    if index not in excused:
                        self._wait(need)
                        return
                elif excused:
                    excused.discard(index)  # caught up: waited for again

    def put(self, payload: Buffer) -> bytes:
        """Write one message into the next slot; return its descriptor (for the datagram)."""
        size = len(payload)
        if size > self.capacity:
            raise ValueError(f"{size} bytes do not fit a slot of {self.capacity}")
        number = self._next
        self._next += 1
        slot = number % self.slots
        start = self._data_at + slot * self.capacity
        generations = self._generations
        generations[slot] = 2 * number - 1  # odd: being written
        self._view[start : start + size] = payload
        generations[slot] = 2 * number
        return DESCRIPTOR.pack(self._pid, self.incarnation, number, size)

    def _holders(self) -> list[int]:
        """Look again where the entries of reliable readers are (their first words' indexes)."""
        entries = self._entries
        self._changes = entries[0]
        held = [
            index
            for index in range(FIRST_ENTRY, 4 * ENTRIES, 4)
            if entries[index] and entries[index + 3] & HOLD
        ]
        tokens = {index: entries[index] for index in held}
        for index, token in list(self._tokens.items()):  # another reader: a clean slate
            if tokens.get(index) != token:
                self._credit.pop(index, None)
                self._excused.discard(index)
        self._tokens = tokens
        self._held = held
        return held

    def _wait(self, need: int) -> None:
        """Wait while a reliable reader that is reading, and within its budget, is behind.

        The time waited is charged to each reader waited for; one that spends more than
        its credit is excused until it caught up (see make_room and _charge).
        """
        entries, clock, hold_ns, excused = (
            self._entries,
            time.monotonic_ns,
            self.hold_ns,
            self._excused,
        )
        last = clock()
        deadline = last + self.max_wait_ns
        waits, step = self.waited, 0
        behind: list[int] = []
        while not self.closed:
            now = clock()
            overdrawn: list[int] = []
            if behind:  # the pause just slept was for these readers
                spent = now - last
                self.waited_ns += spent
                overdrawn = [index for index in behind if self._charge(index, now, spent)]
            last = now
            behind = [
                index
                for index in self._held
                if index not in excused
                and entries[index]
                and entries[index + 1] < need
                and now - entries[index + 2] < hold_ns
            ]
            for index in overdrawn:
                if index in behind:  # (one that caught up meanwhile lost nothing: not excused)
                    excused.add(index)
                    self.excused += 1
                    behind.remove(index)
            if not behind:
                return
            if now >= deadline:
                self.waited_out += 1
                return
            self.waited = waits + 1
            time.sleep(PAUSES[min(step, len(PAUSES) - 1)])
            step += 1

    def _charge(self, index: int, now: int, spent: int) -> bool:
        """Count ``spent`` ns of waiting against a reader: whether it is past its budget.

        Each reader's credit fills at ``budget_ns`` per :data:`WINDOW_NS`, up to
        ``budget_ns``: any stretch of time costs the writer at most that much and a quarter.
        """
        budget = self.budget_ns
        credit = self._credit.get(index)
        if credit is None:
            credit = self._credit[index] = [budget, now]
        else:
            credit[0] = min(budget, credit[0] + (now - credit[1]) * budget // WINDOW_NS)
            credit[1] = now
        credit[0] -= spent
        return credit[0] < 0

    @property
    def written(self) -> int:
        """How many messages were written into the ring."""
        return self._next - 1

    def close(self, unlink: bool = True) -> None:
        """Unmap the ring and (by default) remove its file (idempotent)."""
        if self.closed:
            return
        self.closed = True
        self._generations.release()
        self._entries.release()
        self._view.release()
        self._map.close()
        if unlink:
            with contextlib.suppress(OSError):
                os.unlink(self.path)


class _Mapped:
    """One ring as a reader sees it: read-only (but for its entry), checked before use.

    ``fd`` becomes this object's (closed with it): a reliable reader takes its entry under
    ``flock`` on it, and writes the entry through a mapping of the readers' page alone.
    """

    def __init__(self, fd: int) -> None:
        self.fd = fd
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode) or info.st_uid != os.geteuid():
            raise PermissionError("not a regular file of this user")
        if info.st_mode & 0o077:
            raise PermissionError("readable by other users")
        if info.st_size < PAGE:
            raise ValueError("too small for a ring")
        self.map = mmap.mmap(fd, info.st_size, mmap.MAP_SHARED, mmap.PROT_READ)
        magic, slots, capacity, *_ = HEADER.unpack_from(self.map)
        if (
            magic != MAGIC
            or not 0 < slots <= MAX_SLOTS
            or capacity <= 0
            or segment_size(slots, capacity) != info.st_size
        ):
            self.map.close()
            raise ValueError("not a ring")
        self.slots, self.capacity = slots, capacity
        self.data_at = data_at(slots)
        self.margin = max(1, slots // 16)  # a reader this close to being lapped drops as many
        self.skip_below = 0  # descriptors of older messages are dropped without a look
        self.view = memoryview(self.map)
        self.generations = self.view[GENERATIONS_AT : GENERATIONS_AT + 8 * slots].cast("Q")
        self.entry = -1  # our entry's first word in ``entries`` (-1: none taken)
        self.token = 0
        self._refused = (0, 0)  # when no entry was free, and the page's count of changes then
        self._page: mmap.mmap | None = None
        self.entries: memoryview | None = None

    def claim(self, token: int, number: int) -> bool:
        """Take a free entry for a reliable reader about to read ``number`` (False: none).

        Where none was free, it looks again only once a reader left or a while later.
        """
        refused_at, changes = self._refused
        if refused_at:
            entries = self.entries
            recent = time.monotonic_ns() - refused_at < CLAIM_RETRY_NS
            if recent and (entries is None or entries[0] == changes):
                return False
        try:
            if self.entries is None:
                self._page = mmap.mmap(
                    self.fd, PAGE, mmap.MAP_SHARED, offset=readers_at(self.slots)
                )
                self.entries = memoryview(self._page).cast("Q")
            entries = self.entries
            fcntl.flock(self.fd, fcntl.LOCK_EX)
        except (OSError, ValueError):
            self._refused = (time.monotonic_ns(), 0)
            return False  # (a ring file we may only read: we read without holding it)
        try:
            now = time.monotonic_ns()
            for index in range(FIRST_ENTRY, 4 * ENTRIES, 4):
                if not entries[index] or now - entries[index + 2] >= CLAIM_STALE_NS:
                    entries[index + 1] = number - 1
                    entries[index + 2] = now
                    entries[index + 3] = HOLD
                    entries[index] = token
                    entries[0] += 1  # (the writer looks again)
                    self.entry, self.token = index, token
                    return True
            self._refused = (now, entries[0])
            return False
        finally:
            fcntl.flock(self.fd, fcntl.LOCK_UN)

    def release(self) -> None:
        """Give our entry back (its writer stops waiting for us at once)."""
        entries, entry = self.entries, self.entry
        self.entry = -1
        if entries is None or entry < 0 or self.token >> 32 != os.getpid():
            return  # (a forked child leaves its parent's entry alone)
        if entries[entry] != self.token:
            return
        with contextlib.suppress(OSError):
            fcntl.flock(self.fd, fcntl.LOCK_EX)
        try:
            if entries[entry] == self.token:
                entries[entry + 3] = 0
                entries[entry] = 0
                entries[0] += 1
        finally:
            with contextlib.suppress(OSError):
                fcntl.flock(self.fd, fcntl.LOCK_UN)

    def close(self) -> None:
        self.release()
        if self.entries is not None:
            self.entries.release()
        if self._page is not None:
            self._page.close()
        self.generations.release()
        self.view.release()
        self.map.close()
        os.close(self.fd)


class _Buffers:
    """Buffers messages are copied into, used again once nothing refers to them any more.

    A fresh megabyte costs 256 page faults, more than the copy into it; so each ring size
    keeps enough buffers for the copies one drain holds (:data:`DRAIN_BYTES`) and a few
    more. A delivery hands out a read-only view of one; the view, and every numpy array a
    message builds on it, holds a reference, so a buffer whose only reference is this pool
    is free (CPython's reference count says so exactly). Within one drain the search for a
    free buffer goes on from the last one taken (those before it are held by the drain's
    deliveries); each drain starts again from the first (:meth:`rewind`), so the buffers in
    use are the same few, still in the CPU's cache.
    """

    def __init__(self) -> None:
        self._pools: dict[int, _Pool] = {}

    def take(self, capacity: int, size: int) -> memoryview:
        """A writable view of ``size`` bytes in a buffer nobody else holds."""
        pool = self._pools.get(capacity)
        if pool is None:
            if len(self._pools) >= MAX_MAPS:
                return memoryview(bytearray(size))  # many ring sizes at once: no pooling
            pool = self._pools[capacity] = _Pool(POOLED + DRAIN_BYTES // capacity)
        buffers = pool.buffers
        count = len(buffers)
        at = pool.next
        for _ in range(count):
            buffer = buffers[at]
            at = at + 1 if at + 1 < count else 0
            if sys.getrefcount(buffer) <= _UNUSED:
                pool.next = at
                return memoryview(buffer)
        if count < pool.limit:
            fresh = bytearray(capacity)
            buffers.insert(pool.next, fresh)  # the next turn goes on after it
            pool.next = (pool.next + 1) % len(buffers)
            return memoryview(fresh)
        return memoryview(bytearray(size))  # all in use (a subscriber holds many messages)

    def rewind(self) -> None:
        """Search from the first buffer again (a drain begins)."""
        for pool in self._pools.values():
            pool.next = 0


@dataclass(slots=True)
class _Pool:
    """The buffers of one ring size, and where the next search for a free one starts."""

    limit: int
    buffers: list[bytearray] = field(default_factory=list)
    next: int = 0


class RingReader:
    """A subscriber's side: maps rings on first use and copies messages out of their slots.

    Counts what it could not read: ``overwritten`` (the slot was reused before or while it was
    copied: a slow subscriber) and ``unmapped`` (no such ring of this user, or not a ring).
    """

    def __init__(self, name_of: Namer, on_map: Callable[[], None] | None = None) -> None:
        self._name_of = name_of
        self._on_map = on_map  # told before each new ring is mapped (a cleanup pass)
        self._maps: OrderedDict[tuple[int, int, int, int], _Mapped] = OrderedDict()
        self._buffers = _Buffers()
        self.overwritten = 0
        self.unmapped = 0

    def read(
        self, sender: int, endpoint: int, descriptor: Buffer | mmap.mmap, hold: bool = False
    ) -> memoryview | None:
        """The message a descriptor names (one copy, read-only), or None (counted) if gone.

        With ``hold`` (a reliable subscription reads it), the reader's entry in the ring says
        how far it got, so a reliable writer waits for it (see the module docstring).
        """
        if len(descriptor) != DESCRIPTOR.size:
            self.unmapped += 1
            return None
        pid, incarnation, number, size = DESCRIPTOR.unpack(descriptor)
        ring = self._ring((sender, endpoint, pid, incarnation)) if number > 0 else None
        if ring is None or size > ring.capacity:  # (writers number from 1: 0 was never written)
            self.unmapped += 1
            return None
        if hold:
            data = self._read(ring, number, size)
            entries = ring.entries
            if (
                entries is None
                or ring.entry < 0
                or entries[ring.entry] != ring.token
                or ring.token >> 32 != os.getpid()  # (a forked child: the entry is its parent's)
            ):
                if not ring.claim(_token(), number):
                    return data
                entries = ring.entries
                assert entries is not None
            entry = ring.entry
            entries[entry + 2] = time.monotonic_ns()
            entries[entry + 1] = max(number, ring.skip_below - 1)
            return data
        return self._read(ring, number, size)

    def _read(self, ring: _Mapped, number: int, size: int) -> memoryview | None:
        """Copy message ``number`` of ``size`` bytes out of ``ring`` (None: counted, gone)."""
        if number < ring.skip_below:  # older than what this reader caught up to
            self.overwritten += 1
            return None
        slot = number % ring.slots
        expected = 2 * number
        generations = ring.generations
        if generations[slot] != expected:
            self.overwritten += 1
            return None
        # the writer is (nearly) a ring ahead: it will reuse the slot while we copy. A copy
        # that ends torn costs as much as one that delivers (a reader a ring behind would
        # spend all its time on such copies), so it drops a few messages to make room
        ahead = number + ring.slots - ring.margin  # the writer has begun this message
        if generations[(number - ring.margin) % ring.slots] >= 2 * ahead - 1:
            ring.skip_below = number + ring.margin
            self.overwritten += 1
            return None
        start = ring.data_at + slot * ring.capacity
        data = self._buffers.take(ring.capacity, size)
        data[:size] = ring.view[start : start + size]
        if generations[slot] != expected:  # reused while we copied: the copy may be torn
            self.overwritten += 1
            return None
        return data[:size].toreadonly()

    def rewind(self) -> None:
        """A drain begins: its copies go into the first free buffers again (cache-warm)."""
        self._buffers.rewind()

    def _ring(self, key: tuple[int, int, int, int]) -> _Mapped | None:
        ring = self._maps.get(key)
        if ring is not None:
            self._maps.move_to_end(key)
            return ring
        if self._on_map is not None:
            self._on_map()
        path = self._name_of(*key)
        fd = -1
        for mode in (os.O_RDWR, os.O_RDONLY):  # (read-write for a reliable reader's entry)
            with contextlib.suppress(OSError):
                fd = os.open(path, mode | os.O_NOFOLLOW | os.O_CLOEXEC)
                break
        if fd < 0:
            return None
        try:
            ring = _Mapped(fd)
        except (OSError, ValueError, struct.error):
            os.close(fd)
            return None
        for old in [k for k in self._maps if k[:3] == key[:3] and k[3] < key[3]]:
            self._maps.pop(old).close()  # the ring grew: its older incarnation is done
        if len(self._maps) >= MAX_MAPS:
            self._maps.popitem(last=False)[1].close()
        self._maps[key] = ring
        return ring

    def release(self) -> None:
        """Give back this reader's entries (its receiver closes: no writer waits for it).

        The rings stay mapped: another thread may be copying out of one right now.
        """
        for ring in list(self._maps.values()):
            ring.release()

    def forget(self, sender: int) -> None:
        """Unmap every ring of a process that is gone."""
        for key in [k for k in self._maps if k[0] == sender]:
            self._maps.pop(key).close()

    def close(self) -> None:
        """Unmap every ring."""
        while self._maps:
            self._maps.popitem()[1].close()
