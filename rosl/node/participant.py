"""This process on the bus: transport, discovery, endpoint numbers, and dispatch.

One participant per process (created with the first node, or by a CLI that only observes).
It reaches the network only through the transport seam (:mod:`rosl.bus.transport`): its
receiver is polled on the thread that spins — deliveries go straight to the endpoint's
handler, with no thread hand-off. The discovery thread answers graph queries even while the
user's callbacks run.
"""

from __future__ import annotations

import itertools
import os
import threading
from typing import TYPE_CHECKING, Protocol, cast

from rosl.bus.header import Flags, topic_hash
from rosl.bus.transport import CHANNELS, channel_of, open_transport
from rosl.graph.announce import Discovery

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.coalesce import Flusher
    from rosl.bus.wire import Delivery, Writer
    from rosl.graph.cache import GraphCache
    from rosl.graph.records import NodeRecord
    from rosl.node.lockstep import Answerer


class Handler(Protocol):
    """Something that takes deliveries for one topic or service hash."""

    def deliver(self, delivery: Delivery) -> None:
        """Handle one complete message."""


class Replayer(Protocol):
    """A publisher that keeps history for late transient-local subscribers."""

    def replay(self, target: tuple[int, int]) -> None:
        """Send the kept messages to one subscription (process, endpoint)."""


class Participant:
    """The process's presence on one domain."""

    def __init__(self, domain: int | str | None = None) -> None:
        self.transport = open_transport(domain)
        self.sender = int.from_bytes(os.urandom(8), "little") | 1
        self._receiver = self.transport.receiver()
        self.reader = self._receiver.reader
        self._endpoint_ids = itertools.count(1)
        self._node_ids = itertools.count(1)
        self._describers: dict[int, Callable[[], NodeRecord]] = {}
        self._handlers: dict[int, list[Handler]] = {}
        self._deferred: list[Delivery] = []
        self._lock = threading.RLock()
        self._replayers: dict[str, list[Replayer]] = {}
        self.writers: list[Writer] = []  # the publishers' writers (lock-step answers list them)
        self.answerer: Answerer | None = None  # created when an executor first spins
        self._flusher: Flusher | None = None  # created by the first coalescing publisher
        self.discovery = Discovery(self.transport, self.sender, self._describe)
        self.discovery.handlers["replay"] = self._on_replay_request
        self.discovery.handlers["typedef_request"] = self._on_typedef_request
        self.closed = False
        self.discovery.start()

    @property
    def graph(self) -> GraphCache:
        """What discovery has heard."""
        return self.discovery.cache

    # --- nodes and endpoints -----------------------------------------------------------------

    def add_node(self, describe: Callable[[], NodeRecord]) -> int:
        """Register a node (``describe`` returns its current record); return its index."""
        index = next(self._node_ids)
        self._describers[index] = describe
        return index

    def remove_node(self, index: int) -> None:
        """Forget a node; announce the change."""
        self._describers.pop(index, None)
        self.discovery.changed()

    def _describe(self) -> list[NodeRecord]:
        return [describe() for describe in list(self._describers.values())]

    def next_endpoint(self) -> int:
        """A new endpoint number, unique in this process."""
        return next(self._endpoint_ids) & 0xFFFF

    def add_replayer(self, topic: str, publisher: Replayer) -> None:
        """Register a publisher that answers history requests on ``topic``."""
        with self._lock:
            self._replayers.setdefault(topic, []).append(publisher)

    def remove_replayer(self, topic: str, publisher: Replayer) -> None:
        """Unregister a history-keeping publisher."""
        with self._lock:
            publishers = self._replayers.get(topic, [])
            if publisher in publishers:
                publishers.remove(publisher)

    def _on_replay_request(self, message: dict[str, object]) -> None:
        # runs on the discovery thread: a late transient-local subscription asks for history;
        # its target is [hex sender, endpoint]
        topic = str(message["topic"])
        sender, endpoint = cast("tuple[str, int]", message["target"])
        target = (int(str(sender), 16), int(endpoint))
        with self._lock:
            publishers = list(self._replayers.get(topic, ()))
        for publisher in publishers:
            publisher.replay(target)

    def _on_typedef_request(self, message: dict[str, object]) -> None:
        # runs on the discovery thread: someone (a recorder) needs a type this process uses
        from rosl.idl import registry
        from rosl.idl.errors import InterfaceError

        type_name = str(message["type"])
        if not registry.loaded(type_name):
            return
        try:
            encoding, text = registry.schema(type_name)
            digest = registry.store().type_hash(type_name)
        except InterfaceError:
            return
        self.discovery.send(
            {"op": "typedef", "type": type_name, "encoding": encoding, "text": text, "hash": digest}
        )

    def listen(self, topic: int, handler: Handler) -> None:
        """Deliver messages of a topic/service hash to ``handler`` (joins its channel)."""
        with self._lock:
            self._handlers.setdefault(topic, []).append(handler)
            self.reader.wanted.add(topic)
        self._receiver.join(channel_of(topic))
        self.wake()

    def unlisten(self, topic: int, handler: Handler) -> None:
        """Stop delivering a topic/service hash to ``handler``."""
        with self._lock:
            handlers = self._handlers.get(topic, [])
            if handler in handlers:
                handlers.remove(handler)
            if not handlers:
                self._handlers.pop(topic, None)
                if not self.reader.want_all:
                    self.reader.wanted.discard(topic)

    def listen_all(self) -> None:
        """Receive every topic on every channel (for recorders and monitors)."""
        from rosl.node.lockstep import TOPIC as LOCKSTEP_TOPIC

        with self._lock:
            self.reader.want_all = True
            self.reader.ignored.add(topic_hash(LOCKSTEP_TOPIC))  # lock-step answers: control only
        for channel in range(1, CHANNELS + 1):
            self._receiver.join(channel)
        self.wake()

    # --- receiving ---------------------------------------------------------------------------

    def wake(self) -> None:
        """Wake a thread blocked in :meth:`poll`."""
        self._receiver.wake()

    def poll(self, timeout: float | None, sink: Callable[[Delivery], None] | None = None) -> int:
        """Wait up to ``timeout`` for datagrams, then dispatch every complete message.

        Args:
            timeout: seconds to wait (None: until something arrives or a wake-up).
            sink: receives every delivery instead of the registered handlers (monitors).

        Returns:
            How many messages were dispatched.
        """
        if self.closed:
            return 0
        with self._lock:
            deliveries, self._deferred = self._deferred, []
        pending = bool(deliveries)
        channels = self._receiver.poll(0.0 if pending else timeout, deliveries)
        if channels > 1 or pending:
            deliveries.sort(key=_send_order)  # in the order they were sent, across channels
        for delivery in deliveries:
            if sink is not None:
                sink(delivery)
            else:
                self.dispatch(delivery)
        return len(deliveries)

    def dispatch(self, delivery: Delivery) -> None:
        """Hand one delivery to the handlers of its topic/service hash."""
        handlers = self._handlers.get(delivery.topic, ())
        for handler in handlers:
            handler.deliver(delivery)
        if delivery.flags & _LOCKSTEP and handlers and self.answerer is not None:
            self.answerer.handled(delivery)

    def answer_lockstep(self) -> Answerer:
        """Start answering lock-stepped simulators (announced in this process's record)."""
        if self.answerer is None:
            from rosl.node.lockstep import Answerer

            self.answerer = Answerer(self)
            self.discovery.lockstep = True
            self.discovery.changed()
        return self.answerer

    def defer(self, deliveries: list[Delivery]) -> None:
        """Queue deliveries read by a nested wait for the next :meth:`poll`."""
        with self._lock:
            self._deferred.extend(deliveries)
        self.wake()

    def read_channel(self, channel_topic: int, timeout: float) -> list[Delivery]:
        """Wait up to ``timeout`` on one topic's channel and return what arrived (undispatched).

        Used by blocking calls (``Client.call``) that must not run other callbacks.
        """
        found: list[Delivery] = []
        self._receiver.poll(max(0.0, timeout), found, channel=channel_of(channel_topic))
        return found

    def flusher(self) -> Flusher:
        """The thread that sends coalescing publishers' batches on time (started lazily)."""
        with self._lock:
            if self._flusher is None:
                from rosl.bus.coalesce import Flusher

                self._flusher = Flusher()
            return self._flusher

    def flush(self) -> None:
        """Send what coalescing publishers still hold (a no-op without any)."""
        if self._flusher is not None:
            self._flusher.flush()

    def close(self) -> None:
        """Send pending batches, say goodbye and close the transport (idempotent)."""
        if self.closed:
            return
        if self._flusher is not None:
            self._flusher.close()
        self.closed = True
        self.discovery.stop()
        self.wake()
        self.transport.close()


_LOCKSTEP = int(Flags.LOCKSTEP)  # a plain int: enum operators are slow per message


def _send_order(delivery: Delivery) -> int:
    return delivery.stamp
