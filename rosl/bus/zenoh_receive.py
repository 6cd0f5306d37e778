"""The Zenoh transport's receiving side: samples to deliveries, and the receivers polled above.

A data subscriber's callback (:func:`sample_callback`) turns each Zenoh sample into a
:class:`~rosl.bus.wire.Delivery` at once — its key's hashes computed when it was declared, the
attachment read with one ``struct`` call — and hands it to the receivers of its channel.
A :class:`ZenohReceiver` queues deliveries (and rosl datagrams) in a ``queue.SimpleQueue``:
putting is one C call on Zenoh's thread, and the polling thread blocks in ``get`` and then
takes everything queued, so a burst costs one wake-up, not one per message.
"""

from __future__ import annotations

import queue
import struct
import time
from typing import TYPE_CHECKING, Any

from rosl.bus.header import Kind
from rosl.bus.transport import channel_of
from rosl.bus.wire import Delivery, Reader, StreamStats, place_in_window
from rosl.bus.zenoh_wire import GID_SIZE

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

    import zenoh

    from rosl.bus.zenoh_transport import ZenohTransport

QUEUE_LIMIT = 65536  # deliveries a receiver holds before new ones are dropped
# rmw_zenoh's attachment read in one call: sequence, stamp, GID length, then the GID's first
# 8 bytes (rosl's sender id, little endian) and next 2 (its endpoint); the rest is skipped
_ATTACHMENT = struct.Struct("<qqBQH6x")
_DATA = int(Kind.DATA)
_MASK32 = 0xFFFFFFFF
_new_tuple = tuple.__new__  # a Delivery without its Python-level __new__ (per message)
_WAKE = object()  # queued by wake(): the next poll returns


def read_attachment(data: bytes) -> tuple[int, int, int, int]:
    """(sequence, stamp, sender, endpoint) of an rmw_zenoh attachment; ValueError if malformed."""
    try:
        seq, stamp, length, low, endpoint = _ATTACHMENT.unpack(data)
    except struct.error:
        raise ValueError(f"an attachment has 33 bytes, not {len(data)}") from None
    if length != GID_SIZE:
        raise ValueError(f"the GID's length is {length}, not {GID_SIZE}")
    return seq, stamp, low | 1, endpoint


def sample_callback(
    transport: ZenohTransport, hashes: tuple[int, int] | None, want_all: bool
) -> Callable[[zenoh.Sample], None]:
    """The callback of a data subscriber: its samples as DATA deliveries to the receivers.

    Args:
        transport: whose receivers get the deliveries.
        hashes: (topic, type) hashes of the subscriber's one key; None for a wildcard
            subscriber, which reads them from each sample's key.
        want_all: the wildcard subscriber's samples go to the receivers that want every topic
            (recorders, monitors), a topic subscriber's to the others: a process with both (a
            simulator recording itself) gets each sample from both, and no receiver twice.
    """
    unpack = _ATTACHMENT.unpack
    time_ns = time.time_ns
    identities = transport.identities  # its map is replaced as tokens come and go

    def on_sample(sample: zenoh.Sample) -> None:
        attachment = sample.attachment
        if attachment is None:
            return  # rmw_zenoh drops samples without one too
        try:
            topic, type_ = hashes or transport.key_hashes(str(sample.key_expr))
            data = attachment.to_bytes()
            seq, stamp, length, low, endpoint = unpack(data)
        except (ValueError, struct.error):
            return
        if length != GID_SIZE:
            return
        # a rosl publisher keeps the ids the graph knows it by (see zenoh_identity)
        owner = identities.owners.get(data[17:])
        sender = low | 1 if owner is None else owner[0]
        if owner is not None:
            endpoint = owner[1]
        delivery = _new_tuple(Delivery, (
            _DATA, sender, endpoint, seq & _MASK32, topic, type_, stamp, time_ns(),
            memoryview(sample.payload.to_bytes()), None, 0,
        ))  # fmt: skip
        channel = channel_of(topic)
        for receiver in transport.receivers:
            if channel in receiver.channels and receiver.reader.want_all is want_all:
                receiver.put_delivery(delivery)

    return on_sample


class ZenohReceiver:
    """Deliveries queued by Zenoh's threads; polled by the layers above."""

    def __init__(self, transport: ZenohTransport) -> None:
        self.reader = Reader(None)
        self.channels: set[int] = set()
        self._transport = transport
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._woken = False  # a wake-up taken by a nested poll, owed to the next plain one
        self._closed = False
        self.dropped = 0

    def join(self, channel: int) -> None:
        """Start receiving ``channel`` (every topic when the reader wants all)."""
        self.channels.add(channel)
        if channel and self.reader.want_all:
            self._transport.subscribe_all()

    def leave(self, channel: int) -> None:
        """Stop receiving ``channel``."""
        self.channels.discard(channel)

    def put_delivery(self, delivery: Delivery) -> None:
        """Queue a message for the next poll, when this reader wants its topic."""
        reader = self.reader
        topic = delivery.topic
        if (not reader.want_all and topic not in reader.wanted) or topic in reader.ignored:
            return
        self._put(delivery)

    def put_datagram(self, datagram: bytes) -> None:
        """Queue a rosl datagram (read by the reader at the next poll)."""
        self._put(datagram)

    def _put(self, item: Delivery | bytes) -> None:
        if self._closed:
            return
        if self._queue.qsize() >= QUEUE_LIMIT:
            self.dropped += 1
            return
        self._queue.put(item)

    def poll(
        self,
        timeout: float | None,
        out: list[Delivery],
        channel: int | None = None,
        limits: Mapping[int, int] | None = None,
    ) -> int:
        """Wait for queued messages (or a wake-up) and append them to ``out``.

        ``limits`` is not used: what arrived is queued in this process already.
        """
        if self._closed:
            return 0
        items = self._take(timeout, channel is None)
        datagrams = []
        count = self._count
        for item in items:
            if type(item) is bytes:
                datagrams.append(item)
            elif item.kind != _DATA or count(item):
                out.append(item)
        if datagrams:
            source = iter(datagrams)

            def recv(size: int) -> bytes:
                del size
                try:
                    return next(source)
                except StopIteration:
                    raise BlockingIOError from None

            while self.reader.drain(recv, out):
                pass
        return 1 if items else 0

    def _take(self, timeout: float | None, wakes: bool) -> list[Any]:
        """Everything queued, after waiting up to ``timeout`` for a first item.

        A wake-up ends the wait of a plain poll (``wakes``); a nested poll keeps it for the
        next plain one and waits on.
        """
        if wakes and self._woken:
            self._woken = False
            timeout = 0.0
        deadline = None if timeout is None else time.monotonic() + timeout
        get = self._queue.get
        items: list[Any] = []
        while True:
            try:
                if not items:
                    if deadline is None:
                        item = get()
                    else:
                        item = get(timeout=max(0.0, deadline - time.monotonic()))
                else:
                    item = get(block=False)
            except queue.Empty:
                return items
            if item is _WAKE:
                if self._closed:
                    return []
                if wakes:
                    self._woken = False
                    deadline = time.monotonic()  # take what is queued, wait no longer
                else:
                    self._woken = True
                continue
            if self._closed:
                return []
            items.append(item)

    def _count(self, delivery: Delivery) -> bool:
        """Count a message in its publisher's stream with the multicast reader's own window.

        The same received/lost/duplicate accounting as for datagrams (a gap counts as lost
        until its messages arrive late); False for a duplicate, which is dropped.
        """
        key = (delivery.sender, delivery.endpoint)
        stats = self.reader.streams.get(key)
        if stats is None:
            stats = StreamStats(
                delivery.topic, last_seq=(delivery.seq - 1) & _MASK32,
                last_received=delivery.received,
            )  # fmt: skip
            self.reader.streams[key] = stats
        return place_in_window(stats, delivery.seq, delivery.stamp, delivery.received, True) <= 0

    def wake(self) -> None:
        """Make a blocked (or the next) :meth:`poll` return."""
        self._queue.put(_WAKE)

    def close(self) -> None:
        """Stop receiving (idempotent)."""
        self._closed = True
        self._queue.put(_WAKE)  # a blocked poll returns
        self._transport.forget(self)
