"""Shared memory for large messages between processes of one host: when, where, and cleanup.

Above :func:`threshold` bytes (16 KiB; ``ROSL_SHM_THRESHOLD`` changes it) a publisher whose
matched subscribers all announced this process's :func:`host_identity` writes the message
into its ring (:mod:`rosl.bus.shm_ring`) and sends only a small descriptor datagram, signed
like every other (the hardened bus's key covers it). Everything else — small messages,
service traffic, replays, and any topic with a subscriber on another host — goes over the
wire as before. ``ROSL_SHM=0`` turns the path off (a process with it off announces no
identity, so publishers send it the bytes).

The host identity is the boot id, the network namespace (inode of ``/proc/self/ns/net``),
the user and the ``/dev/shm`` mount (its device): a process in another network namespace
counts as another host (it may be one, behind a veth), another user cannot open our 0600
files, and a container sharing the host's network but with its own ``/dev/shm`` (Docker's
``--network host`` without ``--ipc host``) sees none of our rings.

Where rings live: ``/dev/shm/rosl-u<uid>-d<domain>-p<pid>-<sender>-e<endpoint>-r<n>``,
mode 0600, created with ``O_EXCL|O_NOFOLLOW`` and memory reserved up front; readers open
them only when they are regular files of their own user that nobody else can read.

A ring is about :data:`RING_BYTES`, its slots the first message's size and an eighth more; a
message that outgrows them gets a new ring of slots twice as big. A subscriber that falls
behind by a burst, or by a stall of a loaded machine, is waited for by a reliable publisher
when it is reliable itself (see :mod:`rosl.bus.shm_ring`): rings need not be deeper than
that, and deeper ones cost speed (a reader that far behind reads what has left the CPU's
caches). A forked child leaves its parent's rings to the parent and makes its own.

Lifetime (a lease held by the owning process): a ring is unlinked when its publisher's
transport closes (and at interpreter exit); one replaced by a bigger ring, or whose publisher
was destroyed, at the first message the transport writes :data:`RETIRE_S` seconds later or
more (descriptors of its last messages may still wait in a subscriber's socket, and the
subscriber may not have mapped it yet). A crashed
process leaves its rings behind until the next sweep (:func:`sweep`): when any process of the
user opens shared memory, then at most every :data:`SWEEP_S` seconds while it writes or maps
rings, every ring whose owner (pid, process start time, pid namespace) is no longer running
is unlinked. Subscribers that
mapped it keep reading what they have (an unlinked file stays mapped).
"""

from __future__ import annotations

import contextlib
import errno
import os
import platform
import re
import sys
import threading
import time
import weakref
from typing import TYPE_CHECKING

from rosl.bus.errors import BusError
from rosl.bus.shm_ring import Owner, RingReader, RingWriter, read_owner

if TYPE_CHECKING:
    from collections.abc import Mapping

    from rosl.bus.transport import Buffer

DIRECTORY = "/dev/shm"
# bytes; larger messages take the ring. Measured (bench/bus_throughput.py, 2 cores): from 16 KB
# up, a message costs each side half the CPU it costs over the signed wire (no MAC over the
# payload, no 64 KB datagram to copy through the kernel), and a ring's 1024 slots are 4-16
# times the messages of 16-64 KB a 4 MiB socket buffer holds
THRESHOLD = 16 * 1024
RING_BYTES = 64 * 1024 * 1024  # memory one publisher's ring takes (less where /dev/shm is small)
# slack: 64 MiB of 1 MiB messages is 30 ms at 2 GB/s; 1024 of 60 KB, 60 ms at 1 GB/s
MIN_SLOTS, MAX_SLOTS = 4, 1024
MIN_CAPACITY = 4096
HEADROOM = 8  # a slot holds the first message's size and an eighth more (pages, at least)
SWEEP_S = 30.0
RETIRE_S = 5.0  # a ring replaced by a bigger one (or of a closed publisher) is unlinked this late
STALE_PARTIAL_S = 60.0  # a file with no readable header this old is a half-made ring
_NAME = re.compile(r"^rosl-u(\d+)-d(\d+)-p(\d+)-[0-9a-f]{16}-e\d+-r\d+$")
_OFF = ("0", "off", "false", "no")
_ON = ("", "1", "on", "true", "yes")
_ORDERED_CPUS = ("x86_64", "amd64", "i386", "i686")  # total store order


def enabled(env: Mapping[str, str] | None = None, machine: str | None = None) -> bool:
    """Whether this process may use shared memory (``ROSL_SHM``, and a usable /dev/shm).

    Unset, it is on where the CPU keeps stores in program order (x86-64, which the ring's
    sequence check relies on, see :mod:`rosl.bus.shm_ring`) and off elsewhere (ARM): there
    ``ROSL_SHM=1`` turns it on knowingly.

    Raises:
        BusError: ``ROSL_SHM`` is neither on (1, on, true, yes) nor off (0, off, false, no).
    """
    environ = os.environ if env is None else env
    value = environ.get("ROSL_SHM", "").strip().lower()
    if value in _OFF:
        return False
    if value not in _ON:
        raise BusError(f"ROSL_SHM={value!r} is neither on (1, on, true, yes) nor off (0, off)")
    cpu = (platform.machine() if machine is None else machine).lower()
    if not value and cpu not in _ORDERED_CPUS:
        return False
    return os.path.isdir(DIRECTORY) and os.access(DIRECTORY, os.W_OK | os.X_OK)


def threshold(env: Mapping[str, str] | None = None) -> int:
    """Messages larger than this many bytes take the ring (``ROSL_SHM_THRESHOLD``).

    Raises:
        BusError: ``ROSL_SHM_THRESHOLD`` is not a whole number of bytes from 1.
    """
    text = (os.environ if env is None else env).get("ROSL_SHM_THRESHOLD", "").strip()
    if not text:
        return THRESHOLD
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise BusError(f"ROSL_SHM_THRESHOLD={text!r} is not a number of bytes (1 or more)")
    return value


def host_identity() -> str:
    """Boot id, network namespace, user and /dev/shm mount: equal where rings can be shared."""
    try:
        with open("/proc/sys/kernel/random/boot_id") as handle:
            boot = handle.read().strip()
        netns = os.stat("/proc/self/ns/net").st_ino
        shm = os.stat(DIRECTORY).st_dev  # a container's own tmpfs is another device
    except OSError:
        return ""  # no /proc: no way to tell hosts apart, so never share
    return f"{boot}/{netns}/{os.geteuid()}/{shm}"


def start_time(pid: int) -> int | None:
    """A process's start time in clock ticks since boot (None: no such process)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as handle:
            text = handle.read()
    except OSError:
        return None
    return int(text[text.rindex(b")") + 2 :].split()[19])  # field 22, after "(comm)"


def pid_namespace(pid: int | str = "self") -> int:
    """The inode of a process's pid namespace (0 when unknown)."""
    try:
        return os.stat(f"/proc/{pid}/ns/pid").st_ino
    except OSError:
        return 0


def this_process() -> Owner:
    """The owner record this process writes into its rings."""
    pid = os.getpid()
    return Owner(pid, start_time(pid) or 0, pid_namespace())


def segment_name(
    uid: int, domain: int, pid: int, sender: int, endpoint: int, incarnation: int
) -> str:
    """The file name of a ring (in :data:`DIRECTORY`)."""
    return f"rosl-u{uid}-d{domain}-p{pid}-{sender:016x}-e{endpoint}-r{incarnation}"


def _alive(owner: Owner) -> bool:
    if owner.pid_ns and owner.pid_ns != pid_namespace():
        return True  # another pid namespace's pid: we cannot tell, so leave it
    return start_time(owner.pid) == owner.start_time


def sweep(directory: str = DIRECTORY, uid: int | None = None) -> list[str]:
    """Unlink this user's rings whose owning process is gone; return their names."""
    user = os.geteuid() if uid is None else uid
    removed: list[str] = []
    me = os.getpid()
    try:
        names = os.listdir(directory)
    except OSError:
        return removed
    for name in names:
        match = _NAME.match(name)
        if match is None or int(match[1]) != user or int(match[3]) == me:
            continue
        path = os.path.join(directory, name)
        try:
            info = os.lstat(path)
        except OSError:
            continue
        if info.st_uid != user:
            continue
        owner = read_owner(path)
        if owner is None:
            if time.time() - info.st_mtime < STALE_PARTIAL_S:
                continue  # being created right now
        elif _alive(owner):
            continue
        with contextlib.suppress(OSError):
            os.unlink(path)
            removed.append(name)
    return removed


class SharedMemory:
    """A transport's shared memory: its publishers' rings, readers for its receivers."""

    def __init__(self, domain: int, directory: str = DIRECTORY) -> None:
        self.domain = domain
        self.directory = directory
        self.host = host_identity()
        self.threshold = threshold()
        self.uid = os.geteuid()
        self._owner = this_process()
        self._rings: dict[tuple[int, int], RingWriter] = {}
        # rings no longer written, kept until a deadline for readers that have not mapped
        # them yet (descriptors of their last messages may still wait in a socket)
        self._retired: list[tuple[float, RingWriter]] = []
        self._lock = threading.Lock()
        self._failed = False
        self._next_sweep = time.monotonic() + SWEEP_S
        self._next_due = self._next_sweep  # the next sweep or retirement, whichever is first
        self.swept = sweep(directory, self.uid)  # at start: what crashed processes left
        self._finalizer = weakref.finalize(
            self, _close_rings, self._rings, self._retired, os.getpid()
        )
        _OPEN.add(self)

    def path(self, sender: int, endpoint: int, pid: int, incarnation: int) -> str:
        """Where the ring of one endpoint (of one process start) is."""
        name = segment_name(self.uid, self.domain, pid, sender, endpoint, incarnation)
        return os.path.join(self.directory, name)

    def put(self, sender: int, endpoint: int, payload: Buffer, hold: bool = True) -> bytes | None:
        """Write a message into the endpoint's ring; its descriptor, or None (send the bytes).

        ``hold`` (a reliable publisher): wait, bounded, for reliable readers about to lose
        messages (see :mod:`rosl.bus.shm_ring`).

        The ring is made on first use and made anew, bigger, when a message outgrows it (the
        old one is unlinked :data:`RETIRE_S` later: a subscriber may not have mapped it yet).
        """
        if self._failed:
            return None
        size = len(payload)
        if hold:  # (waits without the lock: other publishers of the process go on)
            ring = self._rings.get((sender, endpoint))
            if ring is not None and size <= ring.capacity:
                with contextlib.suppress(ValueError):  # (closed by another thread meanwhile)
                    ring.make_room()
        with self._lock:
            if time.monotonic() >= self._next_due:
                self._due()
            key = (sender, endpoint)
            ring = self._rings.get(key)
            if ring is None or size > ring.capacity:
                ring = self._grow(key, ring, size)
                if ring is None:
                    return None
            return ring.put(payload)

    def _grow(self, key: tuple[int, int], old: RingWriter | None, size: int) -> RingWriter | None:
        """A ring for messages of ``size`` bytes, in place of ``old`` (None: shm is off)."""
        capacity = max(MIN_CAPACITY, size + size // HEADROOM)
        if old is not None:
            capacity = max(capacity, 2 * old.capacity)  # a growing size: few rings retired
        slots = max(MIN_SLOTS, min(MAX_SLOTS, RING_BYTES // capacity))
        incarnation = 1 if old is None else old.incarnation + 1
        if old is not None:
            self._retire(old)
        path = self.path(*key, self._owner.pid, incarnation)
        try:
            ring = self._make(path, incarnation, slots, capacity)
        except OSError as err:
            self._failed = True
            self._rings.pop(key, None)
            print(
                f"rosl: warning: cannot make a shared-memory ring {path} ({err.strerror}); "
                "large messages go over the network instead",
                file=sys.stderr,
            )
            return None
        self._rings[key] = ring
        return ring

    def _forked(self) -> None:
        """In a child forked from this process: the parent's rings are the parent's.

        They are unmapped here and never unlinked by the child, which writes rings of its own
        (named after its pid) from its first large message on.
        """
        self._lock = threading.Lock()  # (another thread may have held it at the fork)
        self._finalizer.detach()
        for ring in [*self._rings.values(), *(ring for _, ring in self._retired)]:
            ring.close(unlink=False)
        self._rings.clear()
        self._retired.clear()
        self._owner = this_process()
        self._finalizer = weakref.finalize(
            self, _close_rings, self._rings, self._retired, os.getpid()
        )

    def _make(self, path: str, incarnation: int, slots: int, capacity: int) -> RingWriter:
        """A new ring; with fewer slots (less slack) where /dev/shm is small (a container's)."""
        while True:
            try:
                return RingWriter(path, self._owner, incarnation, slots, capacity)
            except OSError as err:
                if err.errno != errno.ENOSPC or slots <= MIN_SLOTS:
                    raise
                slots //= 2

    def drop(self, sender: int, endpoint: int) -> None:
        """An endpoint is gone: unlink its ring (:data:`RETIRE_S` later)."""
        with self._lock:
            ring = self._rings.pop((sender, endpoint), None)
            if ring is not None:
                self._retire(ring)

    def _retire(self, ring: RingWriter) -> None:
        deadline = time.monotonic() + RETIRE_S
        self._retired.append((deadline, ring))
        self._next_due = min(self._next_due, deadline)

    def reader(self) -> RingReader:
        """A reader for one receiver (maps rings of this user and domain on first use)."""
        return RingReader(self.path, self._sweep_soon)

    def _sweep_soon(self) -> None:
        with self._lock:
            if time.monotonic() >= self._next_due:
                self._due()

    def _due(self) -> None:
        """Sweep when due, and unlink retired rings whose time is up (under the lock)."""
        now = time.monotonic()
        if now >= self._next_sweep:
            self._next_sweep = now + SWEEP_S
            sweep(self.directory, self.uid)
        kept = []
        for deadline, ring in self._retired:
            if deadline <= now:
                ring.close()
            else:
                kept.append((deadline, ring))
        self._retired[:] = kept
        self._next_due = min([self._next_sweep, *(deadline for deadline, _ in kept)])

    def close(self) -> None:
        """Unlink every ring this transport made (idempotent)."""
        with self._lock:
            self._finalizer()


_OPEN: weakref.WeakSet[SharedMemory] = weakref.WeakSet()  # this process's, for _after_fork


def _after_fork() -> None:
    for shm in list(_OPEN):
        shm._forked()


os.register_at_fork(after_in_child=_after_fork)


def _close_rings(
    rings: dict[tuple[int, int], RingWriter], retired: list[tuple[float, RingWriter]], owner: int
) -> None:
    # a child forked from the owner (os.fork, multiprocessing) unmaps but must not unlink
    # the rings its parent still writes
    unlink = os.getpid() == owner
    for ring in [*rings.values(), *(ring for _, ring in retired)]:
        ring.close(unlink)
    rings.clear()
    retired.clear()
