"""Messages ↔ datagrams: headers, sequence numbers, fragments, early filtering, loss counts.

A :class:`Writer` sends the messages of one endpoint (a publisher, a service client or
server). A :class:`Reader` turns a receiver's datagrams into deliveries: foreign datagrams and
topics nobody in the process wants are dropped after the header is read, fragments are
reassembled, and each publisher stream's sequence numbers are checked so every gap is counted
— loss is never silent. Callbacks run on the thread that polls; nothing is handed off.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

from rosl.bus import header as hdr
from rosl.bus.coalesce import Batch, split_records
from rosl.bus.fragment import Reassembler, split
from rosl.bus.header import ADDRESS, ADDRESS_SIZE, HEADER, HEADER_SIZE, Flags, Kind
from rosl.bus.transport import channel_of

if TYPE_CHECKING:
    import mmap
    from collections.abc import Callable

    from rosl.bus.coalesce import Flusher
    from rosl.bus.transport import Buffer, Transport

_SMALL = 2048  # below this, joining header and payload beats a scatter send
_unpack_header = HEADER.unpack_from
_new_tuple = tuple.__new__  # builds a Delivery without its Python-level __new__ (per message)
_MAGIC = hdr.MAGIC
_ADDRESSED = int(Flags.ADDRESSED)  # plain ints: enum operators are slow per datagram
_BATCH = int(Flags.BATCH)
_DATA = int(Kind.DATA)
_VERSION = hdr.VERSION


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
    """What one subscriber-side process saw of one publisher's stream."""

    topic: int
    received: int = 0
    lost: int = 0
    last_seq: int = 0
    last_received: int = 0


class Writer:
    """Sends the messages of one endpoint on the channel of its topic or service."""

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
        self.chunk = transport.max_datagram - HEADER_SIZE
        self._seq = itertools.count(1)
        self.sent = 0
        self.last_seq = 0  # the sequence number of the last message sent
        self.flags = 0  # extra header flags for every message (Flags.LOCKSTEP)
        self.batch: Batch | None = None

    def coalesce(self, flusher: Flusher, limit: int) -> None:
        """Send small messages in batches of up to ``limit`` bytes (see ``coalesce.py``)."""
        self.batch = Batch(self._send_batch, min(limit, self.chunk), flusher)

    def flush(self) -> None:
        """Send the small messages a coalescing writer still holds."""
        if self.batch is not None:
            self.batch.flush()

    def _send_batch(self, seq: int, stamp: int, records: bytes) -> None:
        head = HEADER.pack(
            _MAGIC, _VERSION, self.kind, _BATCH, 1, self.sender, seq, self.topic,
            self.type, 0, self.endpoint, len(records), stamp,
        )  # fmt: skip
        self.transport.send(self.channel, [head, records])

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
            stamp: the send time to record (ns); now by default.
        """
        number = (next(self._seq) if seq is None else seq) & 0xFFFFFFFF
        flags = self.flags
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
        if total <= self.chunk:
            head = HEADER.pack(
                _MAGIC, _VERSION, kind_value, flags, 1, self.sender, number, self.topic,
                self.type, 0, self.endpoint, total, when,
            )  # fmt: skip
            if total < _SMALL:
                self.transport.send(self.channel, [head + bytes(payload)])
            else:
                self.transport.send(self.channel, [head, payload])
        else:
            pace = self.transport.pacer
            for index, count, view in split(payload, self.chunk):
                head = HEADER.pack(
                    _MAGIC, _VERSION, kind_value, flags, count, self.sender, number,
                    self.topic, self.type, index, self.endpoint, total, when,
                )  # fmt: skip
                pace.spend(len(view))
                self.transport.send(self.channel, [head, view])
        self.sent += 1
        if seq is None:
            self.last_seq = number
        return number


class Reader:
    """Turns a receiver's datagrams into complete :class:`Delivery` records."""

    def __init__(self) -> None:
        self.wanted: set[int] = set()  # topic hashes someone in this process listens to
        self.want_all = False  # recorders and monitors take every topic
        self.ignored: set[int] = set()  # topic hashes never taken, even with want_all
        self.foreign = 0  # datagrams that are not rosl's (or from another protocol version)
        self.unwanted = 0  # rosl datagrams of topics nobody here listens to
        self.streams: dict[tuple[int, int], StreamStats] = {}
        self.reassembler = Reassembler()
        self._next_expiry = 0

    def drain(self, recv: Callable[[int], bytes], out: list[Delivery], limit: int = 256) -> bool:
        """Read up to ``limit`` ready datagrams with ``recv`` into ``out``.

        ``recv(size)`` returns the next datagram and raises BlockingIOError when there is
        none (a non-blocking socket's ``recv``). Each datagram is its own buffer, so payloads
        are zero-copy views that stay valid after the next read.

        Returns:
            True when the source may hold more (the limit was reached).
        """
        wanted, want_all, ignored = self.wanted, self.want_all, self.ignored
        clock, streams = time.time_ns, self.streams
        if self.reassembler.pending:  # drop (and count) messages whose fragments stopped coming
            now = clock()
            if now >= self._next_expiry:
                self._next_expiry = now + 250_000_000
                self.reassembler.expire(now)
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
            if magic != _MAGIC or version != _VERSION or count == 0 or index >= count:
                self.foreign += 1
                continue
            if (not want_all and topic not in wanted) or topic in ignored:
                self.unwanted += 1
                continue
            if flags & _BATCH:
                self._unbatch(data, kind, flags, sender, endpoint, topic, type_, total, now, out)
                continue
            if count == 1:
                if total != size - HEADER_SIZE:
                    self.reassembler.malformed += 1
                    continue
                payload: memoryview | bytearray | mmap.mmap = memoryview(data)[HEADER_SIZE:]
            else:
                whole = self.reassembler.add(
                    hdr.Header(_MAGIC, version, kind, flags, count, sender, seq, topic, type_,
                               index, endpoint, total, stamp),
                    memoryview(data)[HEADER_SIZE:],
                    now,
                )  # fmt: skip
                if whole is None:
                    continue
                payload = whole
            address = None
            if flags & _ADDRESSED:
                if len(payload) < ADDRESS_SIZE:
                    self.reassembler.malformed += 1
                    continue
                address = ADDRESS.unpack_from(payload)
                payload = memoryview(payload)[ADDRESS_SIZE:]
            if kind == _DATA:
                stats = streams.get((sender, endpoint))
                if stats is None:
                    stats = streams[(sender, endpoint)] = StreamStats(topic, last_seq=seq - 1)
                _advance(stats, seq, now)
            out.append(
                _new_tuple(
                    Delivery,
                    (
                        kind,
                        sender,
                        endpoint,
                        seq,
                        topic,
                        type_,
                        stamp,
                        now,
                        payload,
                        address,
                        flags,
                    ),
                )
            )
        return True

    def _unbatch(
        self,
        data: bytes,
        kind: int,
        flags: int,
        sender: int,
        endpoint: int,
        topic: int,
        type_: int,
        total: int,
        now: int,
        out: list[Delivery],
    ) -> None:
        """Split a coalesced datagram into one delivery per message."""
        if total != len(data) - HEADER_SIZE:
            self.reassembler.malformed += 1
            return
        try:
            records = split_records(memoryview(data)[HEADER_SIZE:])
        except ValueError:
            self.reassembler.malformed += 1
            return
        flags &= ~_BATCH
        stats = None
        if kind == _DATA and records:  # one publisher's stream: looked up once per batch
            key = (sender, endpoint)
            stats = self.streams.get(key)
            if stats is None:
                stats = self.streams[key] = StreamStats(topic, last_seq=records[0][0] - 1)
        for seq, stamp, payload in records:
            if stats is not None:
                _advance(stats, seq, now)
            out.append(
                _new_tuple(
                    Delivery,
                    (kind, sender, endpoint, seq, topic, type_, stamp, now, payload, None, flags),
                )
            )

    def lost(self, topic: int | None = None) -> int:
        """Messages lost (sequence gaps) on all streams, or on one topic's streams."""
        return sum(s.lost for s in self.streams.values() if topic is None or s.topic == topic)

    def received(self, topic: int | None = None) -> int:
        """Messages received on all streams, or on one topic's streams."""
        return sum(s.received for s in self.streams.values() if topic is None or s.topic == topic)


def _advance(stats: StreamStats, seq: int, now: int) -> None:
    """Count one message of a stream, and the gap before it (loss is never silent)."""
    step = (seq - stats.last_seq) & 0xFFFFFFFF
    if 0 < step < 0x80000000:
        stats.lost += step - 1
        stats.last_seq = seq
    stats.received += 1
    stats.last_received = now
