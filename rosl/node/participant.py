"""This process on the bus: transport, discovery, endpoint numbers, and dispatch.

One participant per process (created with the first node, or by a CLI that only observes).
It reaches the network only through the transport seam (:mod:`rosl.bus.transport`): its
receiver is polled by a thread that waits for work (:meth:`Participant.wait`): deliveries go
to their entity's queue, and a single-threaded executor runs them with no thread hand-off.
The discovery thread answers graph queries even while the user's callbacks run.
"""

from __future__ import annotations

import itertools
import os
import threading
import time
from operator import itemgetter
from typing import TYPE_CHECKING, Protocol, cast

from rosl.bus.header import topic_hash
from rosl.bus.transport import CHANNELS, channel_of, open_transport
from rosl.bus.wire import Delivery
from rosl.graph.announce import Discovery
from rosl.node.callback_groups import Queued

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.coalesce import Flusher
    from rosl.bus.wire import Writer
    from rosl.graph.cache import GraphCache
    from rosl.graph.records import NodeRecord
    from rosl.node.lockstep import Answerer


MAX_ASSERTING = 4096  # publishers whose manual liveliness assertions are remembered
_TOPIC_OF = itemgetter(Delivery._fields.index("topic"))  # (read in C, per message)


class Handler(Protocol):
    """Something that takes deliveries for one topic or service hash.

    One that also has ``deliver_all(deliveries)`` is given a poll's deliveries of its topic
    at once, in order, when they are all of that topic (many publishers into one topic);
    it must do what ``deliver`` of each would.
    """

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
        try:
            self._receiver = self.transport.receiver()
        except BaseException:  # a bad setting (BusError): nothing left open behind it
            self.transport.close()
            raise
        self.reader = self._receiver.reader
        self._endpoint_ids = itertools.count(1)
        self._node_ids = itertools.count(1)
        self._describers: dict[int, Callable[[], NodeRecord]] = {}
        self._handlers: dict[int, list[Handler]] = {}
        # per topic, what takes a poll's deliveries of it at once (rebuilt from _handlers)
        self._takers: dict[int, tuple[Callable[[list[Delivery]], None], ...]] = {}
        self._limits: dict[int, int] = {}  # channel -> datagrams one poll reads (see listen)
        self._lock = threading.RLock()
        # executors waiting for work; reentrant: a signal handler may notify() while the
        # thread it interrupted holds it
        self._cond = threading.Condition(threading.RLock())
        self._waiting = 0  # threads asleep on _cond
        self._poll_lock = threading.Lock()  # one thread polls the receiver at a time
        self._poller: int | None = None  # that thread
        self.changes = 0  # counts notify() calls: a waiter that computed its timeout from an
        # older state returns at once (see wait)
        self._replayers: dict[str, list[Replayer]] = {}
        self.writers: list[Writer] = []  # the publishers' writers (lock-step answers list them)
        self.answerer: Answerer | None = None  # created when an executor first spins
        self._flusher: Flusher | None = None  # created by the first coalescing publisher
        self.discovery = Discovery(self.transport, self.sender, self._describe)
        self.discovery.handlers["replay"] = self._on_replay_request
        self.discovery.handlers["typedef_request"] = self._on_typedef_request
        # manual-by-topic liveliness: (process, endpoint) -> when it last asserted (ns)
        self.asserted: dict[tuple[int, int], int] = {}
        self.discovery.handlers["liveliness"] = self._on_liveliness
        self.discovery.on_gone.append(self.reader.forget)  # its streams' state is retired
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

    def _on_liveliness(self, message: dict[str, object]) -> None:
        # runs on the discovery thread: a publisher asserted its liveliness (see qos_watch)
        key = (int(str(message["sender"]), 16), int(cast("int", message["endpoint"])))
        if len(self.asserted) >= MAX_ASSERTING and key not in self.asserted:
            self.asserted.clear()  # strangers' ids must not grow it; live ones assert again
        self.asserted[key] = time.monotonic_ns()  # when heard here (a local duration)

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
            self._limit_reads()
            self._retake()
        self._receiver.join(channel_of(topic))
        self.notify()

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
            self._limit_reads()
            self._retake()

    def _retake(self) -> None:
        """Rebuild what takes a topic's deliveries at once (under ``_lock``)."""
        self._takers = {topic: tuple(map(_taker, handlers))
                        for topic, handlers in self._handlers.items()}  # fmt: skip
        self.rehold()

    def rehold(self) -> None:
        """Say again which topics a holding subscription takes (after one changed its mind).

        Their shared-memory writers wait for this process's reads (see rosl.bus.shm_ring).
        """
        with self._lock:
            self.reader.held = {
                topic
                for topic, handlers in self._handlers.items()
                if any(getattr(handler, "holding", False) for handler in handlers)
            }

    def _limit_reads(self) -> None:
        """Per channel, the shallowest queue its messages go to: what one poll should read.

        Reading more than a keep-last queue holds would push messages out of it that the
        socket's buffer could have kept until the executor got to them (many publishers
        into one subscriber). A channel with a tap (a monitor, a recorder) is not limited.
        """
        limits: dict[int, int] = {}
        unlimited = set(range(CHANNELS + 1)) if self.reader.want_all else set()
        for topic, handlers in self._handlers.items():
            channel = channel_of(topic)
            for handler in handlers:
                depth = handler.queue_limit if isinstance(handler, Queued) else None
                if depth is None:
                    unlimited.add(channel)
                else:
                    limits[channel] = min(depth, limits.get(channel, depth))
        self._limits = {c: n for c, n in limits.items() if c not in unlimited}

    def listen_all(self) -> None:
        """Receive every topic on every channel (for recorders and monitors)."""
        from rosl.node.lockstep import TOPIC as LOCKSTEP_TOPIC

        with self._lock:
            self.reader.want_all = True
            self.reader.ignored.add(topic_hash(LOCKSTEP_TOPIC))  # lock-step answers: control only
            self._limit_reads()
        for channel in range(1, CHANNELS + 1):
            self._receiver.join(channel)
        self.notify()

    # --- receiving ---------------------------------------------------------------------------

    def notify(self) -> None:
        """Something an executor waits for changed: wake the threads in :meth:`wait`.

        A thread blocked polling the receiver is woken too (also when it is the caller: a
        signal handler runs on the thread blocked in the poll).
        """
        self.changes += 1
        if self._poller is not None:
            self._receiver.wake()
        if self._waiting:
            with self._cond:
                self._cond.notify_all()

    def unwatched(self) -> bool:
        """Whether no thread is waiting in :meth:`wait` or polling (one that would want a wake)."""
        return self._poller is None and not self._waiting

    def wait_change(self, timeout: float, since: int) -> bool:
        """Whether anything changed since ``since`` within ``timeout`` seconds.

        :meth:`wait` given ``since``, trimmed for an executor whose nodes only wait for their
        next timer (a 1 kHz timer asks a thousand times a second): one poll, when no other
        thread is polling.
        """
        if self.changes != since:
            return True
        if not self._poll_once(timeout, since):
            return self.wait(_never, timeout, since)
        return self.changes != since

    def _poll_once(self, timeout: float | None, snapshot: int) -> bool:
        """Poll once unless another thread is polling (False) or ``changes`` moved."""
        if self.closed or not self._poll_lock.acquire(blocking=False):
            return False
        try:
            self._poller = threading.get_ident()
            if self.changes == snapshot:  # else something changed: look again first
                self._poll_locked(timeout, None)
        finally:
            self._poller = None
            self._poll_lock.release()
            if self._waiting:  # another thread may take over polling, or was served
                with self._cond:
                    self._cond.notify_all()
        return True

    def wait(
        self, ready: Callable[[], bool], timeout: float | None, since: int | None = None
    ) -> bool:
        """Block until ``ready()`` or ``timeout`` seconds (None: no limit); return ``ready()``.

        Meanwhile the receiver is polled by one waiting thread at a time (the others sleep
        until it has dispatched): a single-threaded executor reads its own deliveries, with
        no thread hand-off. With ``since`` (a :attr:`changes` value read before the caller
        looked for work), it returns True as soon as anything changed since then — a
        dispatch or a :meth:`notify` — or False at the timeout, and leaves the looking to the
        caller (``ready`` is not called then: a look per wake-up is the caller's).
        """
        deadline = None if timeout is None else time.monotonic() + max(0.0, timeout)
        first = True
        while True:
            # user code (ready) runs with no lock held; under locks only `changes` is compared
            snapshot = self.changes
            if since is not None:
                if snapshot != since:
                    return True
            elif ready():
                return True
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None:
                if remaining <= 0 and not first:
                    return False if since is not None else ready()
                remaining = max(0.0, remaining)
            first = False
            if self._poll_once(remaining, snapshot):
                if since is not None and remaining is not None and self.changes == since:
                    return False  # the poll's time is up (or it woke for nothing: look again)
                continue
            with self._cond:
                self._waiting += 1
                try:
                    # sleep only while someone polls and nothing changed since the look above
                    if self.changes == snapshot and (self._poll_lock.locked() or self.closed):
                        self._cond.wait(0.1 if remaining is None and self.closed else remaining)
                finally:
                    self._waiting -= 1

    def poll(self, timeout: float | None, sink: Callable[[Delivery], None] | None = None) -> int:
        """Wait up to ``timeout`` for datagrams, then dispatch every complete message.

        Args:
            timeout: seconds to wait (None: until something arrives or a wake-up).
            sink: receives every delivery instead of the registered handlers (monitors).

        Returns:
            How many messages were dispatched (0 when another thread was polling
            throughout ``timeout``: it dispatches them).
        """
        if self.closed:
            return 0
        if not self._poll_lock.acquire(timeout=-1 if timeout is None else max(0.0, timeout)):
            return 0
        try:
            self._poller = threading.get_ident()
            count = self._poll_locked(timeout, sink)
        finally:
            self._poller = None
            self._poll_lock.release()
        if count and self._waiting:
            with self._cond:
                self._cond.notify_all()
        return count

    def _poll_locked(self, timeout: float | None, sink: Callable[[Delivery], None] | None) -> int:
        deliveries: list[Delivery] = []
        limits = self._limits if sink is None else None  # a sink takes everything at once
        channels = self._receiver.poll(timeout, deliveries, None, limits)
        if channels > 1:
            deliveries.sort(key=_send_order)  # in the order they were sent, across channels
        if sink is not None:
            for delivery in deliveries:
                sink(delivery)
        elif deliveries:
            topics = list(map(_TOPIC_OF, deliveries))
            if topics.count(topics[0]) == len(topics):  # one topic (fan-in): all at once
                for take in self._takers.get(topics[0], ()):
                    take(deliveries)
            else:  # each to the handlers of its topic: node entities queue it for their
                # executor, taps (monitors, the lock-step end) take it here, on this thread
                handlers = self._handlers
                for delivery in deliveries:
                    for handler in handlers.get(delivery.topic, ()):
                        handler.deliver(delivery)
        if deliveries:
            self.changes += 1  # queues filled: waiters look again
        return len(deliveries)

    def answer_lockstep(self) -> Answerer:
        """Start answering lock-stepped simulators (announced in this process's record)."""
        if self.answerer is None:
            from rosl.node.lockstep import Answerer

            self.answerer = Answerer(self)
            self.discovery.lockstep = True
            self.discovery.changed()
        return self.answerer

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
        self.notify()
        self.transport.close()


def _send_order(delivery: Delivery) -> int:
    return delivery.stamp


def _taker(handler: Handler) -> Callable[[list[Delivery]], None]:
    """What hands a handler a poll's deliveries of its topic: its ``deliver_all``, or each."""
    deliver_all: Callable[[list[Delivery]], None] | None = getattr(handler, "deliver_all", None)
    if deliver_all is not None:
        return deliver_all
    deliver = handler.deliver

    def each(deliveries: list[Delivery]) -> None:
        for delivery in deliveries:
            deliver(delivery)

    return each


def _never() -> bool:
    return False
