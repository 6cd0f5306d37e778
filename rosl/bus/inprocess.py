"""A transport inside one process: datagrams handed between receivers through queues.

For tests of the seam (``ROSL_TRANSPORT=inprocess``): every participant of the process on the
same domain shares one hub, and a datagram sent on a channel is queued, as its own bytes, for
every receiver that joined that channel — the sender's own included, as multicast loops back.
Receivers run the same :class:`~rosl.bus.wire.Reader` as the multicast transport, so
fragmentation, filtering and loss counting are exercised unchanged. Nothing leaves the process.
"""

from __future__ import annotations

import collections
import threading
from typing import TYPE_CHECKING, Literal

from rosl.bus import auth as keys
from rosl.bus.pacing import pacer_from_env
from rosl.bus.wire import Reader

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    from rosl.bus.auth import Auth
    from rosl.bus.transport import Buffer
    from rosl.bus.wire import Delivery

MAX_DATAGRAM = 65000  # as multicast on loopback, so large messages are fragmented the same way
QUEUE_LIMIT = 4096  # datagrams a receiver holds per channel before new ones are dropped


class _Hub:
    """The receivers of one domain, by channel."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.members: dict[int, list[InProcessReceiver]] = {}


_hubs: dict[int, _Hub] = {}
_hubs_lock = threading.Lock()


def _hub(domain: int) -> _Hub:
    with _hubs_lock:
        return _hubs.setdefault(domain, _Hub())


class InProcessTransport:
    """The process-local bus of one domain."""

    def __init__(self, domain: int, auth: Auth | Literal["env"] | None = "env") -> None:
        self.auth = keys.load(domain) if auth == "env" else auth  # signed as on the wire
        self.name = "the in-process bus"
        self.fix_hint = "the receiver must join channel 0 before the first send"
        self.domain = domain
        self.max_datagram = MAX_DATAGRAM
        self.pacer = pacer_from_env(True)
        self._hub = _hub(domain)
        self._receivers: list[InProcessReceiver] = []
        self.send_errors = 0

    def send(self, channel: int, parts: Sequence[Buffer]) -> None:
        """Queue one datagram for every receiver of ``channel`` (a full queue drops it)."""
        data = b"".join(parts)
        with self._hub.lock:
            members = list(self._hub.members.get(channel, ()))
        for receiver in members:
            if not receiver.put(channel, data):
                self.send_errors += 1

    def receiver(self) -> InProcessReceiver:
        """A new receiver on this domain's hub."""
        receiver = InProcessReceiver(self._hub, self.auth)
        self._receivers.append(receiver)
        return receiver

    def describe(self) -> str:
        """Where the traffic goes."""
        return f"domain {self.domain} of this process"

    def close(self) -> None:
        """Close every receiver made here (idempotent)."""
        receivers, self._receivers = self._receivers, []
        for receiver in receivers:
            receiver.close()


class InProcessReceiver:
    """Queues per channel, waited on with a condition variable."""

    def __init__(self, hub: _Hub, auth: Auth | None = None) -> None:
        self.reader = Reader(auth)
        self._hub = hub
        self._queues: dict[int, collections.deque[bytes]] = {}
        self._ready = threading.Condition()
        self._woken = False
        self._closed = False

    def put(self, channel: int, data: bytes) -> bool:
        """Queue a datagram (the hub calls this); False when the queue is full."""
        with self._ready:
            queue = self._queues.get(channel)
            if queue is None:
                return True  # left meanwhile
            if len(queue) >= QUEUE_LIMIT:
                return False
            queue.append(data)
            self._ready.notify_all()
        return True

    def join(self, channel: int) -> None:
        """Start queueing the channel's datagrams."""
        with self._ready:
            if channel in self._queues or self._closed:
                return
            self._queues[channel] = collections.deque()
        with self._hub.lock:
            self._hub.members.setdefault(channel, []).append(self)

    def leave(self, channel: int) -> None:
        """Stop queueing the channel's datagrams and drop those held."""
        with self._hub.lock:
            members = self._hub.members.get(channel, [])
            if self in members:
                members.remove(self)
        with self._ready:
            self._queues.pop(channel, None)

    def poll(
        self,
        timeout: float | None,
        out: list[Delivery],
        channel: int | None = None,
        limits: Mapping[int, int] | None = None,
    ) -> int:
        """Wait for queued datagrams (or a wake-up) and append complete messages to ``out``.

        ``limits`` is not used: what arrived is queued in this process already.
        """
        with self._ready:
            if self._closed:
                return 0
            if not self._has_data(channel) and not (channel is None and self._woken):
                self._ready.wait(timeout)
            if channel is None:
                self._woken = False
            batches = [
                (number, list(queue))
                for number, queue in self._queues.items()
                if queue and (channel is None or number == channel)
            ]
            for number, _ in batches:
                self._queues[number].clear()
        for _, datagrams in batches:
            recv = _Source(datagrams).recv
            while self.reader.drain(recv, out):
                pass
        return len(batches)

    def _has_data(self, channel: int | None) -> bool:
        if channel is None:
            return any(self._queues.values())
        return bool(self._queues.get(channel))

    def wake(self) -> None:
        """Make a blocked (or the next) :meth:`poll` return."""
        with self._ready:
            self._woken = True
            self._ready.notify_all()

    def close(self) -> None:
        """Leave every channel (idempotent)."""
        for channel in list(self._queues):
            self.leave(channel)
        with self._ready:
            self._closed = True
            self._ready.notify_all()


class _Source:
    """Datagrams read like a non-blocking socket: ``recv`` until BlockingIOError."""

    def __init__(self, datagrams: list[bytes]) -> None:
        self._datagrams = iter(datagrams)

    def recv(self, size: int) -> bytes:
        del size
        try:
            return next(self._datagrams)
        except StopIteration:
            raise BlockingIOError from None
