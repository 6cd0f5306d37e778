"""Messages ↔ datagrams: headers, MACs, sequence windows, fragments, early filtering, loss.

A :class:`Writer` sends the messages of one endpoint (a publisher, a service client or
server), signed when the transport has a key. A :class:`Reader` turns a receiver's datagrams
into deliveries, and is where strangers' traffic stops:

* foreign datagrams and topics nobody in the process wants are dropped after the header is
  read; unsigned or wrongly signed ones before anything else is: no state, no parsing;
* every stream — one endpoint of one process start (the sender id is drawn per start), and
  for addressed datagrams one target — keeps a sliding window over its sequence numbers: a
  message seen before is never delivered twice (duplicates, replays), and a gap is counted as
  loss only when it is at most :data:`LOSS_WINDOW` long; a bigger jump starts a new segment
  of the stream (logged once). A gap longer than :data:`DUP_WINDOW` counts only once the next
  message goes on from after it, and a late message inside the window takes its gap back out
  of the count, so a forged sequence number never leaves the count inflated while the real
  stream goes on, and counts of real gaps stay exact;
* a datagram outside its stream's window, or opening a stream, is taken only if its stamp
  is newer than anything that stream sent before and within :data:`FRESH_NS` of this clock:
  old datagrams replayed later are dropped as stale;
* state is bounded: at most :data:`MAX_STREAMS` streams (silent ones are retired first into a
  bounded table that keeps replay protection), and fragments share one reassembly budget.

Callbacks run on the thread that polls; nothing is handed off.
"""

from __future__ import annotations

import itertools
import struct
import sys
import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

from rosl.bus import header as hdr
from rosl.bus.auth import MAC_SIZE, SMALL
from rosl.bus.coalesce import Batch, split_records
from rosl.bus.fragment import Reassembler, split
from rosl.bus.header import ADDRESS, ADDRESS_SIZE, HEADER, HEADER_SIZE, Flags, Kind
from rosl.bus.shm_ring import DRAIN_BYTES
from rosl.bus.transport import channel_of

if TYPE_CHECKING:
    import mmap
    from collections.abc import Callable, Sequence

    from rosl.bus.auth import Auth
    from rosl.bus.coalesce import Flusher
    from rosl.bus.shm import SharedMemory
    from rosl.bus.shm_ring import RingReader
    from rosl.bus.transport import Buffer, Transport

_SMALL = 2048  # below this, joining header and payload beats a scatter send
# HEADER in three runs: the fields a writer's plain messages share up to ``seq`` (magic,
# version, kind, flags, count, sender) and after it (topic, type, index, endpoint), packed once
_HEAD_START = struct.Struct("<2sBBBxHQ")
_HEAD_END = struct.Struct("<QIHH")
_PLAIN = struct.Struct(f"<{_HEAD_START.size}sI{_HEAD_END.size}sIq")  # start, seq, end, total, stamp
_time_ns = time.time_ns
# the header as the receive path reads it: HEADER with the magic as a number (no bytes object
# made per datagram)
_unpack_header = struct.Struct("<H" + HEADER.format[3:]).unpack_from
_new_tuple = tuple.__new__  # builds a Delivery without its Python-level __new__ (per message)
_MAGIC = hdr.MAGIC
_MAGIC_LE = int.from_bytes(_MAGIC, "little")
_ADDRESSED = int(Flags.ADDRESSED)  # plain ints: enum operators are slow per datagram
_BATCH = int(Flags.BATCH)
_SIGNED = int(Flags.SIGNED)
_SHM = int(Flags.SHM)
_UNCOMMON = _BATCH | _ADDRESSED | _SHM  # what the receive path's common case never carries
_DATA = int(Kind.DATA)
_VERSION = hdr.VERSION

DUP_WINDOW = 1024  # sequence numbers behind the newest that are still told apart
LOSS_WINDOW = 1 << 16  # a forward gap up to this is loss; a bigger jump starts a new segment
FRESH_NS = 30_000_000_000  # every datagram must be stamped this close to the receiver's clock
BORN_SLACK_NS = 1_000_000_000  # a new stream's datagrams may predate the reader by this much
MAX_STREAMS = 8192  # streams followed at once (each kind of stream has its own table)
MAX_RETIRED = 16384  # streams forgotten but still protected against replays
SILENT_NS = 10_000_000_000  # a stream silent this long is retired
HOUSEKEEPING_NS = 250_000_000
# one drain copies at most about this much out of shared memory: the copies of a poll are held
# together, and fresh memory for each (page faults) costs more than the copy itself
SHM_DRAIN_BYTES = DRAIN_BYTES
MAX_JUMP_LOGS = 10
_FULL = (1 << DUP_WINDOW) - 1
_MASK32 = 0xFFFFFFFF
ACCEPTED, JUMPED, DUPLICATE, STALE = 0, -1, 1, 2  # > 0: dropped


class Delivery(NamedTuple):
    """A complete message received from the bus."""

    kind: int
    sender: int
    endpoint: int
    seq: int
    topic: int
    type: int
    stamp: int  # send time (ns)
    received: int  # receive time (ns), taken when the last datagram was read
    payload: memoryview | bytearray | mmap.mmap
    address: tuple[int, int, int] | None = None  # (process, endpoint, correlation)
    flags: int = 0  # header flags (Flags.LOCKSTEP matters to subscribers)


@dataclass(slots=True)
class StreamStats:
    """What one receiving process saw of one stream (a publisher's, for ``DATA``).

    ``last_seq`` is the newest sequence number; bit ``i`` of ``seen`` says whether
    ``last_seq - i`` arrived (numbers before the stream's first are taken as seen).
    """

    topic: int
    received: int = 0
    lost: int = 0
    last_seq: int = 0
    last_received: int = 0
    seen: int = _FULL
    stamp: int = 0  # the newest datagram stamp of the stream (the sender's clock)
    jumps: int = 0  # new segments started by a jump beyond the windows
    pending: int = 0  # a gap bigger than DUP_WINDOW, counted when the stream goes on after it
    # the segment a big gap or jump left: (last_seq, seen, stamp, pending, lost)
    left: tuple[int, int, int, int, int] | None = None
    run: int = 2  # messages since the current segment began (a new stream counts as known)


def place_in_window(stats: StreamStats, seq: int, stamp: int, now: int, loss: bool) -> int:
    """Place one message in its stream's window: ACCEPTED or JUMPED, else DUPLICATE or STALE.

    Inside :data:`DUP_WINDOW` of the newest number the bitmap decides. Leaving it (a gap of
    more than DUP_WINDOW, a step back past it, a far jump) takes a stamp newer than anything
    the stream sent, and keeps the segment left behind: a later message that goes on from it
    (the real stream, after a key holder's forged detour) returns to it, its loss count too.

    Args:
        stats: the stream.
        seq: the message's sequence number.
        stamp: the datagram's (signed) send stamp.
        now: the receive time (ns).
        loss: count gaps as lost messages (publisher streams).
    """
    result = ACCEPTED
    step = (seq - stats.last_seq) & _MASK32
    if 0 < step <= DUP_WINDOW:
        if loss:
            if stats.pending:  # the stream went on from after the big gap: it was real
                stats.lost += stats.pending
                stats.pending = 0
            stats.lost += step - 1
        stats.seen = ((stats.seen << step) | 1) & _FULL
        stats.last_seq = seq
    else:
        back = (stats.last_seq - seq) & _MASK32
        if back < DUP_WINDOW:
            bit = 1 << back
            if stats.seen & bit:
                return DUPLICATE
            stats.seen |= bit
            if loss:  # it was counted lost when the stream went past it
                if stats.pending:
                    stats.pending -= 1
                elif stats.lost:
                    stats.lost -= 1
        else:
            left = stats.left
            if (
                left is not None
                and stamp > left[2]
                and _continues(left[0], seq)
                and not _continues(stats.last_seq, seq)  # a second real gap goes on from here
            ):
                stats.last_seq, stats.seen, stats.stamp, stats.pending, stats.lost = left
                stats.left = None  # back on the segment a detour left
                return place_in_window(stats, seq, stamp, now, loss)
            if stamp <= stats.stamp:
                return STALE
            if stats.left is None or stats.run > 1:  # a segment of one message (a jump nothing
                # went on from) is not worth returning to: keep the one left before it
                stats.left = (stats.last_seq, stats.seen, stats.stamp, stats.pending, stats.lost)
            stats.run = 0
            if step <= LOSS_WINDOW:  # a big gap: counted when the next message goes on after it
                if loss:
                    stats.lost += stats.pending
                    stats.pending = step - 1
                stats.seen = 1
            else:  # a new segment: nothing counted
                stats.seen = _FULL
                stats.pending = 0
                stats.jumps += 1
                result = JUMPED
            stats.last_seq = seq
    stats.run += 1
    if stamp > stats.stamp:  # a stamp ahead of our clock counts as now: it cannot hold the
        stats.stamp = min(stamp, now + BORN_SLACK_NS)  # stream back until it comes true
    stats.received += 1
    stats.last_received = now
    return result


def _continues(last_seq: int, seq: int) -> bool:
    """Whether ``seq`` goes on from a segment whose newest number is ``last_seq``."""
    return 0 < (seq - last_seq) & _MASK32 <= LOSS_WINDOW


class Writer:
    """Sends the messages of one endpoint on the channel of its topic or service.

    :meth:`send` takes every option; ``send_plain(payload)`` is ``send(payload)`` without
    them (a publisher's messages), by the way the writer's settings pick when they change
    (:meth:`_choose`): a small message becomes its datagram in a few calls.
    """

    def __init__(
        self,
        transport: Transport,
        sender: int,
        endpoint: int,
        name: str,
        type_name: str,
        kind: Kind = Kind.DATA,
        channel: int | None = None,
    ) -> None:
        self.transport = transport
        self.sender = sender
        self.endpoint = endpoint
        self.kind = kind
        self.topic = hdr.topic_hash(name)
        self.type = hdr.type_hash(type_name)
        self.channel = channel_of(self.topic) if channel is None else channel
        self.chunk = transport.max_datagram - HEADER_SIZE - MAC_SIZE
        self._seq = itertools.count(1)
        self.sent = 0
        self.last_seq = 0  # the sequence number of the last message sent
        self._flags = 0
        self.batch: Batch | None = None
        self.auth: Auth | None = transport.auth
        self._signed = 0 if self.auth is None else _SIGNED
        self.shm: SharedMemory | None = None  # see use_shm
        self._shm_gate: Callable[[], bool] = _never
        self.shm_hold = True  # reliable: wait (bounded) for reliable readers of the ring
        self.shm_sent = 0  # messages sent as shared-memory descriptors
        register = getattr(transport, "register_writer", None)
        if register is not None:  # a transport that routes by name (Zenoh)
            register(self.topic, name, type_name, int(kind))
        # a transport's short way for plain messages, with no rosl header (Zenoh's puts)
        self._direct: Callable[[Buffer, int, int], None] | None = None
        direct = getattr(transport, "direct_sender", None)
        if direct is not None and self.auth is None:
            self._direct = direct(self.topic, sender, endpoint, int(kind))
        # a plain message's datagram in one call per step: the header's two constant runs,
        # the transport's send of one buffer on this channel, the MAC
        one = getattr(transport, "datagram_sender", None)
        self._emit: Callable[[Buffer], None] = (
            _one_part(transport.send, self.channel) if one is None else one(self.channel)
        )
        self._sign: Callable[[bytes], bytes] | None = (
            None if self.auth is None else self.auth.small_signer()
        )
        self._head_end = _HEAD_END.pack(self.topic, self.type, 0, endpoint)
        self._head_start = b""
        self._plain_below = 0
        self.send_plain: Callable[[Buffer], int] = self.send
        self._choose()

    @property
    def flags(self) -> int:
        """Extra header flags for every message (Flags.LOCKSTEP)."""
        return self._flags

    @flags.setter
    def flags(self, value: int) -> None:
        if self.batch is not None:  # what it holds goes first, as send() does it
            self.batch.flush()
        self._flags = int(value)
        self._choose()

    def _choose(self) -> None:
        """Pick :meth:`send_plain`'s way for the writer's settings (on every change of them)."""
        flags, batch = self._flags, self.batch
        self._head_start = _HEAD_START.pack(
            _MAGIC, _VERSION, self.kind, flags | self._signed, 1, self.sender
        )
        below = min(_SMALL, self.chunk + 1)
        if self._sign is not None:  # its datagram within what small_signer signs
            below = min(below, SMALL - HEADER_SIZE + 1)
        if self.shm is not None:
            below = min(below, self.shm.threshold + 1)
        self._plain_below = below
        if self._direct is not None and not flags and batch is None:
            self.send_plain = self._send_direct
        elif batch is not None and not flags:
            self.send_plain = self._send_batched
        else:
            self.send_plain = self._send_datagram

    def coalesce(self, flusher: Flusher, limit: int) -> None:
        """Send small messages in batches of up to ``limit`` bytes (see ``coalesce.py``)."""
        self.batch = Batch(self._send_batch, min(limit, self.chunk), flusher)
        self._choose()

    def use_shm(self, gate: Callable[[], bool]) -> None:
        """Send large messages through shared memory while ``gate()`` allows it.

        ``gate()`` says whether every receiver can map this host's rings (see ``shm.py``);
        a no-op on transports without shared memory.
        """
        shm = getattr(self.transport, "shm", None)
        if shm is not None and self.kind == Kind.DATA:
            self.shm, self._shm_gate = shm, gate
            self._choose()

    def close(self) -> None:
        """Release what the writer holds beyond the transport (its shared-memory ring)."""
        if self.shm is not None:
            self.shm.drop(self.sender, self.endpoint)
            self.shm = None

    def flush(self) -> None:
        """Send the small messages a coalescing writer still holds."""
        if self.batch is not None:
            self.batch.flush()

    def _send_batch(self, seq: int, stamp: int, records: bytes | bytearray) -> None:
        head = HEADER.pack(
            _MAGIC, _VERSION, self.kind, _BATCH | self._signed, 1, self.sender, seq,
            self.topic, self.type, 0, self.endpoint, len(records), stamp,
        )  # fmt: skip
        auth = self.auth  # (what _send does, one call less: a batch is sent once a millisecond)
        parts: list[Buffer] = [head, records]
        if auth is not None:
            parts.append(auth.mac_parts(parts))
        self.transport.send(self.channel, parts)

    def _send(self, parts: list[Buffer]) -> None:
        """Send one datagram, with its MAC when there is a key."""
        if self.auth is not None:
            parts.append(self.auth.mac_parts(parts))
        self.transport.send(self.channel, parts)

    # --- send_plain: send(payload) with no options, by the writer's settings (see _choose) -----

    def _send_datagram(self, payload: Buffer) -> int:
        """A small plain message as one datagram; anything else as :meth:`send` does."""
        total = len(payload)
        if total >= self._plain_below:  # shared memory, a scatter send, fragments
            return self.send(payload)
        number = next(self._seq) & _MASK32
        data = _PLAIN.pack(self._head_start, number, self._head_end, total, _time_ns()) + payload
        sign = self._sign
        self._emit(data if sign is None else sign(data))
        self.sent += 1
        self.last_seq = number
        return number

    def _send_direct(self, payload: Buffer) -> int:
        """A plain message through the transport's direct sender (no rosl header)."""
        direct = self._direct
        if direct is None:  # (never: chosen only with one)
            return self.send(payload)
        number = next(self._seq) & _MASK32
        direct(payload, number, _time_ns())
        self.sent += 1
        self.last_seq = number
        return number

    def _send_batched(self, payload: Buffer) -> int:
        """A plain message into the batch when it fits; else as :meth:`send` does."""
        batch = self.batch
        if batch is None or not batch.fits(len(payload)):
            return self.send(payload)
        number = next(self._seq) & _MASK32
        batch.add(number, _time_ns(), payload)
        self.sent += 1
        self.last_seq = number
        return number

    def send(
        self,
        payload: Buffer,
        *,
        kind: Kind | None = None,
        address: tuple[int, int, int] | None = None,
        seq: int | None = None,
        stamp: int | None = None,
    ) -> int:
        """Send one message; return its sequence number.

        Args:
            payload: the message bytes (CDR).
            kind: overrides the writer's kind (e.g. REPLAY for a publisher).
            address: (process, endpoint, correlation) for a message meant for one endpoint.
            seq: reuse a sequence number (a replayed message keeps its original one).
            stamp: the send time to record (ns); now by default. Receivers take a stream's
                first message only when its stamp is within ``FRESH_NS`` of their clock.
        """
        number = (next(self._seq) if seq is None else seq) & 0xFFFFFFFF
        flags = self._flags
        direct = self._direct
        if direct is not None and kind is None and address is None and not (flags or self.batch):
            direct(payload, number, time.time_ns() if stamp is None else stamp)
            self.sent += 1
            if seq is None:
                self.last_seq = number
            return number
        if address is not None:
            payload = ADDRESS.pack(*address) + bytes(payload)
            flags |= _ADDRESSED
        total = len(payload)
        when = time.time_ns() if stamp is None else stamp
        kind_value = self.kind if kind is None else kind
        batch = self.batch
        if batch is not None:
            if flags == 0 and kind_value == self.kind and batch.fits(total):  # plain, small
                batch.add(number, when, payload)
                self.sent += 1
                if seq is None:
                    self.last_seq = number
                return number
            batch.flush()  # what is pending goes first: the stream stays in order
        shm = self.shm
        if (
            shm is not None
            and total > shm.threshold
            and address is None
            and kind_value == _DATA
            and self._shm_gate()
        ):
            descriptor = shm.put(self.sender, self.endpoint, payload, self.shm_hold)
            if descriptor is not None:  # else: no ring (no room): the bytes go as they are
                payload, total, flags = descriptor, len(descriptor), flags | _SHM
                self.shm_sent += 1
        flags |= self._signed
        if total <= self.chunk:
            head = HEADER.pack(
                _MAGIC, _VERSION, kind_value, flags, 1, self.sender, number, self.topic,
                self.type, 0, self.endpoint, total, when,
            )  # fmt: skip
            if total < _SMALL:  # one buffer, joined once
                if self.auth is None:
                    self.transport.send(self.channel, [head + bytes(payload)])
                else:
                    self.transport.send(self.channel, [self.auth.signed(head + bytes(payload))])
            else:
                self._send([head, payload])
        else:
            pace = self.transport.pacer
            for index, count, view in split(payload, self.chunk):
                head = HEADER.pack(
                    _MAGIC, _VERSION, kind_value, flags, count, self.sender, number,
                    self.topic, self.type, index, self.endpoint, total, when,
                )  # fmt: skip
                pace.spend(len(view))
                self._send([head, view])
        self.sent += 1
        if seq is None:
            self.last_seq = number
        return number

    def send_all(self, payloads: list[bytes], flush: bool = False) -> None:
        """Send plain messages in order, stamped now: a batching writer adds them in one loop.

        The same as :meth:`send` for each (numbers, counts, batches), without its options'
        per-message cost; a message too big for a batch, or a writer that does not batch,
        goes through :meth:`send`. With ``flush``, then :meth:`flush`.
        """
        batch = self.batch
        if not payloads:
            if flush:
                self.flush()
            return
        if batch is None or self._flags or not batch.fits(max(map(len, payloads))):
            for payload in payloads:  # (a big one keeps its place)
                self.send(payload)
            if flush:
                self.flush()
            return
        count = len(payloads)
        # reserve count consecutive numbers in one C call (islice over the counter runs without
        # a thread switch in CPython), so a send() on another thread cannot take one of them
        first = next(itertools.islice(self._seq, count - 1, None)) - (count - 1)
        batch.add_all(first, time.time_ns(), payloads, flush)
        self.sent += count
        self.last_seq = (first + count - 1) & 0xFFFFFFFF


class Reader:
    """Turns a receiver's datagrams into complete :class:`Delivery` records."""

    def __init__(self, auth: Auth | None = None) -> None:
        self.auth = auth
        self.wanted: set[int] = set()  # topic hashes someone in this process listens to
        self.want_all = False  # recorders and monitors take every topic
        self.ignored: set[int] = set()  # topic hashes never taken, even with want_all
        self.foreign = 0  # datagrams that are not rosl's (or from another protocol version)
        self.unsigned = 0  # rosl datagrams without a MAC (a sender with ROSL_KEY=none)
        self.forged = 0  # rosl datagrams whose MAC is wrong (another key: another user)
        self.unwanted = 0  # rosl datagrams of topics nobody here listens to
        self.duplicates = 0  # messages seen before (resent or replayed)
        self.stale = 0  # datagrams too old for their stream (replays), or stamped far off
        self.shm: RingReader | None = None  # maps publishers' rings (None: shm off here)
        self.held: set[int] = set()  # topics a reliable subscription takes (see _from_shm)
        self.unmappable = 0  # shared-memory descriptors with shm off here
        self.retired = 0  # streams forgotten (silent, evicted, or their process said bye)
        self.streams: dict[tuple[int, int], StreamStats] = {}  # publishers: (process, endpoint)
        # every other stream: (process, endpoint, kind, target process, target endpoint)
        self.others: dict[tuple[int, ...], StreamStats] = {}
        self.reassembler = Reassembler()
        self.log: Callable[[str], None] = _log
        self._retired: dict[tuple[int, ...], tuple[int, int]] = {}  # key -> (last_seq, stamp)
        self._folded: dict[int, list[int]] = {}  # topic -> [received, lost] of retired streams
        self._gone: deque[int] = deque(maxlen=MAX_RETIRED)  # said goodbye: retired at next look
        self._born = time.time_ns()
        self._lock = threading.Lock()  # retiring against counting (other threads count)
        self._next_housekeeping = 0
        self._jump_logs = 0

    # --- the receive path (per datagram: keep it lean) ----------------------------------------

    def drain(self, recv: Callable[[int], bytes], out: list[Delivery], limit: int = 256) -> bool:
        """Read up to ``limit`` ready datagrams with ``recv`` into ``out``.

        ``recv(size)`` returns the next datagram and raises BlockingIOError when there is
        none (a non-blocking socket's ``recv``). Each datagram is its own buffer, so payloads
        are zero-copy views that stay valid after the next read.

        Returns:
            True when the source may hold more (the limit was reached).
        """
        wanted, want_all, ignored = self.wanted, self.want_all, self.ignored
        clock, streams, append = time.time_ns, self.streams, out.append
        verify = None if self.auth is None else self.auth.verify
        copied = 0  # bytes copied out of shared memory by this call
        if self.shm is not None:
            self.shm.rewind()
        now = clock()
        if now >= self._next_housekeeping:
            self._housekeeping(now)
        for _ in range(limit):
            try:
                data = recv(65536)
            except (BlockingIOError, InterruptedError):
                return False
            except OSError:
                return False  # closed while draining (shutdown)
            now = clock()
            size = len(data)
            if size < HEADER_SIZE:
                self.foreign += 1
                continue
            (magic, version, kind, flags, count, sender, seq, topic, type_, index,
             endpoint, total, stamp) = _unpack_header(data)  # fmt: skip
            if magic != _MAGIC_LE or version != _VERSION or index >= count:  # (count 0 too)
                self.foreign += 1
                continue
            if (topic not in wanted and not want_all) or (ignored and topic in ignored):
                self.unwanted += 1  # read no further (and spend no MAC on it)
                continue
            if flags & _SIGNED:
                size -= MAC_SIZE
                flags ^= _SIGNED  # a wire detail: deliveries carry the message's flags
                if verify is not None and not verify(data):
                    self.forged += 1
                    continue
            elif verify is not None:
                self.unsigned += 1
                continue
            if not -FRESH_NS <= now - stamp <= FRESH_NS:
                self.stale += 1  # captured long ago, or a clock far off: never delivered
                continue
            if kind != _DATA or count != 1 or flags & _UNCOMMON:
                copied += self._accept(data, size, kind, flags, count, sender, seq, topic,
                                       type_, index, endpoint, total, stamp, now, out)  # fmt: skip
                if copied >= SHM_DRAIN_BYTES:
                    return True  # the rest stays in the socket: copies are freed before more
                continue
            # the common case, a whole message on a topic (what _accept does for it, with the
            # window's usual step inline)
            stats = streams.get((sender, endpoint))
            if stats is None:
                stats = self._open(streams, (sender, endpoint), topic, seq, stamp, now)
                if stats is None:
                    continue
            if total != size - HEADER_SIZE:
                self.reassembler.malformed += 1
                continue
            if (seq - stats.last_seq) & _MASK32 == 1 and not stats.pending:
                seen = stats.seen  # (place_in_window's next-in-line case, nothing lost)
                if seen != _FULL:
                    stats.seen = ((seen << 1) | 1) & _FULL
                stats.last_seq = seq
                stats.run += 1
                if stamp > stats.stamp:
                    stats.stamp = min(stamp, now + BORN_SLACK_NS)
                stats.received += 1
                stats.last_received = now
            else:
                verdict = place_in_window(stats, seq, stamp, now, True)
                if verdict:
                    if verdict > 0:
                        self._refuse(verdict)
                        continue
                    self._jumped(sender, endpoint, stats)
            append(
                _new_tuple(
                    Delivery,
                    (kind, sender, endpoint, seq, topic, type_, stamp, now,
                     memoryview(data)[HEADER_SIZE:size], None, flags),
                )
            )  # fmt: skip
        return True

    def _accept(
        self,
        data: bytes,
        size: int,
        kind: int,
        flags: int,
        count: int,
        sender: int,
        seq: int,
        topic: int,
        type_: int,
        index: int,
        endpoint: int,
        total: int,
        stamp: int,
        now: int,
        out: list[Delivery],
    ) -> int:
        """Take one checked datagram that is not a plain whole message (see :meth:`drain`).

        Batches, fragments, addressed and shared-memory messages, and every kind but
        ``DATA``. Returns the bytes it copied out of shared memory.
        """
        if flags & _BATCH:
            self._unbatch(data, size, kind, flags, sender, endpoint, topic, type_, total,
                          stamp, now, out)  # fmt: skip
            return 0
        stats = None
        if kind == _DATA:
            stats = self.streams.get((sender, endpoint))
            if stats is None:
                stats = self._open(self.streams, (sender, endpoint), topic, seq, stamp, now)
                if stats is None:
                    return 0
            elif count > 1 and _seen(stats, seq):
                self.duplicates += 1  # a fragment of a message delivered already
                return 0
        if count == 1:
            if total != size - HEADER_SIZE:
                self.reassembler.malformed += 1
                return 0
            payload: memoryview | bytearray | mmap.mmap = memoryview(data)[HEADER_SIZE:size]
        else:
            whole = self.reassembler.add(
                hdr.Header(_MAGIC, _VERSION, kind, flags, count, sender, seq, topic, type_,
                           index, endpoint, total, stamp),
                memoryview(data)[HEADER_SIZE:size],
                now,
            )  # fmt: skip
            if whole is None:
                return 0
            payload = whole
        address = None
        if flags & _ADDRESSED:
            if len(payload) < ADDRESS_SIZE:
                self.reassembler.malformed += 1
                return 0
            address = ADDRESS.unpack_from(payload)
            payload = memoryview(payload)[ADDRESS_SIZE:]
        if stats is None:  # requests, responses, replays, discovery: no loss counted
            key = (sender, endpoint, kind, *(address or (0, 0))[:2])
            stats = self.others.get(key)
            if stats is None:
                stats = self._open(self.others, key, topic, seq, stamp, now)
                if stats is None:
                    return 0
            verdict = place_in_window(stats, seq, stamp, now, False)
        else:
            verdict = place_in_window(stats, seq, stamp, now, True)
        if verdict:
            if verdict > 0:
                self._refuse(verdict)
                return 0
            if kind == _DATA:  # a server's replies to one client skip numbers by design
                self._jumped(sender, endpoint, stats)
        copied = 0
        if flags & _SHM:
            resolved = self._from_shm(sender, endpoint, payload, stats, topic in self.held)
            if resolved is None:
                return 0
            payload, flags = resolved, flags ^ _SHM
            copied = len(resolved)
        fields = (kind, sender, endpoint, seq, topic, type_, stamp, now, payload, address, flags)
        out.append(_new_tuple(Delivery, fields))
        return copied

    def _unbatch(
        self,
        data: bytes,
        size: int,
        kind: int,
        flags: int,
        sender: int,
        endpoint: int,
        topic: int,
        type_: int,
        total: int,
        stamp: int,
        now: int,
        out: list[Delivery],
    ) -> None:
        """Split a coalesced datagram into one delivery per new message."""
        if total != size - HEADER_SIZE:
            self.reassembler.malformed += 1
            return
        try:
            records = split_records(memoryview(data)[HEADER_SIZE:size])
        except ValueError:
            self.reassembler.malformed += 1
            return
        if not records:
            return
        flags &= ~_BATCH
        loss = kind == _DATA
        table: dict[Any, StreamStats] = self.streams if loss else self.others
        key: tuple[int, ...] = (sender, endpoint) if loss else (sender, endpoint, kind, 0, 0)
        stats = table.get(key)  # one stream: looked up once per batch
        if stats is None:
            stats = self._open(table, key, topic, records[0][0], stamp, now)
            if stats is None:
                return
        for seq, message_stamp, payload in records:
            # the datagram's stamp is signed, not the records'
            verdict = place_in_window(stats, seq, stamp, now, loss)
            if verdict:
                if verdict > 0:
                    self._refuse(verdict)
                    continue
                if loss:
                    self._jumped(sender, endpoint, stats)
            fields = (kind, sender, endpoint, seq, topic, type_, message_stamp, now, payload,
                      None, flags)  # fmt: skip
            out.append(_new_tuple(Delivery, fields))

    def _from_shm(
        self,
        sender: int,
        endpoint: int,
        descriptor: Buffer | mmap.mmap,
        stats: StreamStats,
        hold: bool,
    ) -> memoryview | None:
        """The message a shared-memory descriptor names; None (counted as lost) when gone.

        ``hold``: a reliable subscription of this process takes the topic, so the ring's
        writer waits for this reader (see :mod:`rosl.bus.shm_ring`).
        """
        shm = self.shm
        data = None if shm is None else shm.read(sender, endpoint, descriptor, hold)
        if data is None:
            if shm is None:
                self.unmappable += 1
            stats.received -= 1  # counted as received by its window: it was lost instead
            stats.lost += 1
            return None
        return data  # read-only: the deserializer keeps array views of it

    # --- streams ---------------------------------------------------------------------------------

    def _open(
        self,
        table: dict[Any, StreamStats],
        key: tuple[int, ...],
        topic: int,
        seq: int,
        stamp: int,
        now: int,
    ) -> StreamStats | None:
        """Start following a stream, or None when its first datagram is stale (a replay).

        A retired stream comes back with its window (numbers up to its last are taken as
        seen, so its old datagrams stay refused); a new one must have been sent after this
        reader began, give or take :data:`BORN_SLACK_NS`: a datagram captured before that
        and replayed now is refused, even to a process started since.
        """
        retired = self._retired.pop(key, None)
        if retired is not None:
            last_seq, last_stamp = retired
            stats = StreamStats(topic, last_seq=last_seq, last_received=now, stamp=last_stamp)
        elif stamp < self._born - BORN_SLACK_NS:
            self.stale += 1
            return None
        else:
            stats = StreamStats(topic, last_seq=(seq - 1) & _MASK32, last_received=now)
        if len(table) >= MAX_STREAMS:
            self._evict(table, now)
        table[key] = stats
        return stats

    def _refuse(self, verdict: int) -> None:
        if verdict == DUPLICATE:
            self.duplicates += 1
        else:
            self.stale += 1

    def _jumped(self, sender: int, endpoint: int, stats: StreamStats) -> None:
        """Say once per stream (and a few times per process) that a stream jumped."""
        if stats.jumps > 1 or self._jump_logs >= MAX_JUMP_LOGS:
            return
        self._jump_logs += 1
        more = "" if self._jump_logs < MAX_JUMP_LOGS else " (further jumps are not logged)"
        self.log(
            f"bus: the stream of endpoint {endpoint} of process {sender:016x} jumped to "
            f"sequence number {stats.last_seq}; loss is counted from there (a forged or "
            f"corrupted datagram, or more than {LOSS_WINDOW} messages lost at once){more}"
        )

    def forget(self, sender: int) -> None:
        """A process said goodbye: retire its streams (at the next look; any thread)."""
        self._gone.append(sender)  # bounded: a reader nobody polls must not grow either

    def _housekeeping(self, now: int) -> None:
        """Expire fragments, retire silent streams and those of processes that said bye."""
        self._next_housekeeping = now + HOUSEKEEPING_NS
        if self.reassembler.pending:  # drop (and count) messages whose fragments stopped
            self.reassembler.expire(now)
        gone = set()
        while self._gone:
            gone.add(self._gone.popleft())
        if self.shm is not None:
            for sender in gone:
                self.shm.forget(sender)  # unmap its rings (the polling thread owns them)
        for table in (self.streams, self.others):
            for key, stats in list(table.items()):
                if key[0] in gone or now - stats.last_received > SILENT_NS:
                    self._retire(table, key)

    def _evict(self, table: dict[Any, StreamStats], now: int) -> None:
        """Make room in a full table: retire silent streams, else the least recently heard."""
        for key, stats in list(table.items()):
            if now - stats.last_received > SILENT_NS:
                self._retire(table, key)
        if len(table) >= MAX_STREAMS:
            by_age = sorted(table.items(), key=lambda item: item[1].last_received)
            for key, _ in by_age[: MAX_STREAMS // 4]:
                self._retire(table, key)

    def _retire(self, table: dict[Any, StreamStats], key: tuple[int, ...]) -> None:
        with self._lock:
            stats = table.pop(key, None)
            if stats is None:
                return
            self.retired += 1
            if len(self._retired) >= MAX_RETIRED:
                del self._retired[next(iter(self._retired))]  # the oldest retirement
            self._retired[key] = (stats.last_seq, stats.stamp)
            wanted = self.want_all or stats.topic in self.wanted
            if table is self.streams and wanted and len(self._folded) < MAX_STREAMS:
                folded = self._folded.setdefault(stats.topic, [0, 0])
                folded[0] += stats.received
                folded[1] += stats.lost

    # --- counts (any thread) ---------------------------------------------------------------------

    def lost(self, topic: int | None = None) -> int:
        """Messages lost (sequence gaps) on all publisher streams, or on one topic's."""
        return self._count(1, topic)

    def received(self, topic: int | None = None) -> int:
        """Messages received on all publisher streams, or on one topic's."""
        return self._count(0, topic)

    def lost_by_publisher(self, topic: int) -> dict[tuple[int, int], int]:
        """Messages lost (sequence gaps) per publisher (process, endpoint) followed on a topic.

        Only publishers with loss; retired streams are in :meth:`lost` only.
        """
        with self._lock:
            live = tuple(self.streams.items())
        return {key: s.lost for key, s in live if s.topic == topic and s.lost}

    def _count(self, field: int, topic: int | None) -> int:
        # snapshots: the polling thread adds and retires streams while other threads count
        with self._lock:
            live = tuple(self.streams.values())
            folded = tuple(self._folded.items())
        total = sum(f[1][field] for f in folded if topic is None or f[0] == topic)
        if field:
            return total + sum(s.lost for s in live if topic is None or s.topic == topic)
        return total + sum(s.received for s in live if topic is None or s.topic == topic)

    def dropped(self) -> dict[str, int]:
        """What this reader refused, by reason (for rosl doctor and the fuzz tests)."""
        return {
            "foreign": self.foreign,
            "unsigned": self.unsigned,
            "forged": self.forged,
            "duplicates": self.duplicates,
            "stale": self.stale,
            "malformed": self.reassembler.malformed,
            "incomplete": self.reassembler.incomplete,
            "evicted": self.reassembler.evicted,
            "overwritten": 0 if self.shm is None else self.shm.overwritten,
            "unmapped": self.unmappable + (0 if self.shm is None else self.shm.unmapped),
        }


def _seen(stats: StreamStats, seq: int) -> bool:
    """Whether a stream already delivered ``seq`` (inside its window)."""
    back = (stats.last_seq - seq) & _MASK32
    return back < DUP_WINDOW and bool(stats.seen >> back & 1)


def _never() -> bool:
    return False


def _one_part(
    send: Callable[[int, Sequence[Buffer]], None], channel: int
) -> Callable[[Buffer], None]:
    """A transport's ``send`` of one buffer on one channel (one without ``datagram_sender``)."""

    def emit(data: Buffer) -> None:
        send(channel, (data,))

    return emit


def _log(line: str) -> None:
    print(f"rosl: {line}", file=sys.stderr, flush=True)
