"""Publishers: serialize once, send on the topic's channel, keep history when transient-local.

``coalesce=True`` (or ``ROSL_COALESCE=1`` for every publisher of a process) sends small
messages in batches of one datagram, at most a millisecond late: several times the messages
per second of one datagram each, for streams of small messages (see ``rosl/bus/coalesce.py``).
:meth:`Publisher.hold_until_flush` batches the same way with no timer thread: the caller
flushes (the simulator does, once a millisecond of wall time).
"""

from __future__ import annotations

import collections
import os
import time
from typing import TYPE_CHECKING, cast

from rosl.bus.coalesce import DEFAULT_BYTES, Flusher
from rosl.bus.header import Kind
from rosl.bus.wire import Writer
from rosl.graph.records import PUBLISHER, SUBSCRIPTION, EndpointRecord
from rosl.idl import registry
from rosl.node.qos import MANUAL, ReliabilityPolicy, duration_ns

_monotonic_ns = time.monotonic_ns

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.idl.messages import Message
    from rosl.node.node import Node
    from rosl.node.qos import QoSProfile


class Publisher:
    """Publishes messages of one type on one topic (rclpy.publisher.Publisher)."""

    def __init__(
        self,
        node: Node,
        msg_type: type[Message],
        topic: str,
        qos: QoSProfile,
        coalesce: bool | None = None,
    ) -> None:
        self.node = node
        self.msg_type = msg_type
        self.qos_profile = qos
        self.topic = topic
        self.type_name = msg_type.__msgtype__
        participant = node.participant
        self.endpoint = participant.next_endpoint()
        self._writer = Writer(
            participant.transport, participant.sender, self.endpoint, topic, self.type_name
        )
        participant.writers.append(self._writer)
        shm = getattr(participant.transport, "shm", None)
        if shm is not None and shm.host:
            self._writer.use_shm(_LocalSubscribers(node, topic, shm.host))
            self._writer.shm_hold = qos.reliability is not ReliabilityPolicy.BEST_EFFORT
        if coalesce is None:
            coalesce = os.environ.get("ROSL_COALESCE", "").strip().lower() in ("1", "true", "yes")
        if coalesce:
            self._writer.coalesce(participant.flusher(), DEFAULT_BYTES)
        self._store = registry.store()
        self.digest = registry.digest(self.type_name)
        # for type(msg) is msg_type: made at the first publish (a node's /rosout and
        # /parameter_events publishers may never send)
        self._serialize_own: Callable[[Message], bytes | memoryview] = self._first_serialize
        self._history: collections.deque[tuple[int, int, bytes | memoryview]] | None = (
            collections.deque(maxlen=max(1, qos.depth)) if qos.keeps_history else None
        )
        self.destroyed = False
        if self._history is not None:
            participant.add_replayer(topic, self)
            keep = getattr(participant.transport, "keep_history", None)
            if keep is not None:  # a transport that keeps history itself (Zenoh's caches)
                reliable = qos.reliability is not ReliabilityPolicy.BEST_EFFORT
                keep(self._writer.topic, max(1, qos.depth), reliable)
        # QoS events (see qos_watch): deadline, lifespan, manual-by-topic liveliness
        # (local durations: the monotonic clock, which no clock step moves)
        self.last_published_ns: int | None = None
        self.last_asserted_ns = time.monotonic_ns()
        self.alive = True  # a manual-by-topic publisher whose lease has not run out
        self._lifespan_ns = duration_ns(qos.lifespan)
        self._lease_ns = duration_ns(qos.liveliness_lease_duration)
        self._manual = qos.liveliness in MANUAL
        self._keeps = self._manual or self._history is not None  # publish records more
        self._announced_ns = 0  # when assert_liveliness last told the subscriptions

    @property
    def topic_name(self) -> str:
        """The fully qualified topic name."""
        return self.topic

    def publish(self, msg: Message | bytes | bytearray | memoryview) -> None:
        """Send one message (or already-serialized CDR bytes).

        It blocks on subscribers only as a DDS reliable writer does: a reliable publisher
        of a large message through shared memory waits (100 ms at most) for a reliable
        subscription of this host that is reading but about to lose messages (see
        :mod:`rosl.bus.shm_ring`).
        """
        if type(msg) is self.msg_type:  # the common case, checked no further
            data: bytes | memoryview = self._serialize_own(msg)  # bytes or a view: any sends
        else:
            data = self._payload(msg)
        seq = self._writer.send_plain(data)
        now = self.last_published_ns = _monotonic_ns()
        if self._keeps:
            if self._manual:
                self.last_asserted_ns, self.alive = now, True
            if self._history is not None:
                self._history.append((seq, now, data))

    def _payload(self, msg: object) -> bytes | memoryview:
        """What :meth:`publish` sends for anything but a message of the publisher's class.

        Raises:
            TypeError: ``msg`` is neither bytes nor a message of the publisher's type.
        """
        if isinstance(msg, (bytes, bytearray, memoryview)):
            return bytes(msg)
        type_name = getattr(msg, "__msgtype__", None)
        if type_name != self.type_name:
            got = type_name or type(msg).__name__
            raise TypeError(f"publisher on {self.topic} sends {self.type_name}, not {got}")
        return self._store.serializer(self.type_name)(cast("Message", msg))

    def _first_serialize(self, msg: Message) -> bytes | memoryview:
        """Make the publisher's serializer (once), then serialize as it does."""
        self._serialize_own = self._store.class_serializer(self.msg_type)
        return self._serialize_own(msg)

    def publish_all(self, payloads: list[bytes], flush: bool = False) -> None:
        """Send already-serialized messages in order, as :meth:`publish` each would.

        For a caller that queues its own messages between flushes: a batching publisher adds
        them in one loop rather than one call each; with ``flush``, then :meth:`flush`.
        """
        if not payloads:
            return
        if self._history is not None or self._manual:  # each needs its own record
            for payload in payloads:
                self.publish(payload)
            if flush:
                self.flush()
            return
        self._writer.send_all(payloads, flush)
        self.last_published_ns = time.monotonic_ns()  # as publish(): a local duration

    def replay(self, target: tuple[int, int]) -> None:
        """Send the kept history to one late subscriber (transient local)."""
        if self._history is None or self.destroyed:
            return
        oldest = time.monotonic_ns() - self._lifespan_ns if self._lifespan_ns else 0
        for seq, stamp, data in list(self._history):
            if stamp < oldest:
                continue  # past its lifespan: a late subscriber never sees it
            self._writer.send(data, kind=Kind.REPLAY, address=(*target, 0), seq=seq)

    def get_subscription_count(self) -> int:
        """How many subscriptions the graph shows on this topic."""
        return self.node.participant.graph.count(SUBSCRIPTION, self.topic)

    def wait_for_subscribers(self, count: int, timeout: float) -> int:
        """Block until ``count`` subscriptions are matched (or the timeout); return how many."""
        graph = self.node.participant.graph
        graph.wait_for(lambda: graph.count(SUBSCRIPTION, self.topic) >= count, timeout)
        return graph.count(SUBSCRIPTION, self.topic)

    def record(self) -> EndpointRecord:
        """This publisher as discovery announces it."""
        return EndpointRecord(
            PUBLISHER, self.topic, self.type_name, self.endpoint, self.qos_profile.words(),
            {"sent": self._writer.sent}, self.digest,
        )  # fmt: skip

    def flush(self) -> None:
        """Send the messages a coalescing publisher still holds (a no-op otherwise)."""
        self._writer.flush()

    def hold_until_flush(self, limit: int = DEFAULT_BYTES) -> None:
        """Batch small messages until :meth:`flush` (or a full batch); no timer sends them.

        For a caller that flushes on its own schedule from its own thread: no second thread
        wakes every millisecond to contend for the GIL. ``limit``: a batch's payload bound in
        bytes (at most what one datagram carries).
        """
        self._writer.coalesce(_HeldByCaller(), limit)

    def destroy(self) -> None:
        """Stop publishing (rclpy: node.destroy_publisher)."""
        self.node.destroy_publisher(self)

    def assert_liveliness(self) -> None:
        """Tell matched subscriptions this publisher is alive (manual-by-topic liveliness).

        Automatic liveliness is asserted by discovery; calls closer together than a quarter
        of the lease (or 50 ms) send nothing more.
        """
        now = time.monotonic_ns()
        self.last_asserted_ns, self.alive = now, True
        if not self._manual or now - self._announced_ns < max(self._lease_ns // 4, 50_000_000):
            return  # automatic: discovery asserts it
        self._announced_ns = now
        participant = self.node.participant
        participant.discovery.send(
            {"op": "liveliness", "sender": f"{participant.sender:016x}", "endpoint": self.endpoint}
        )


class _LocalSubscribers:
    """Whether every subscription of a topic is in a process that maps this host's rings.

    Asked per large message; answered from the graph, again only when the graph changed.
    """

    def __init__(self, node: Node, topic: str, host: str) -> None:
        self._graph = node.participant.graph
        self._topic = topic
        self._host = host
        self._generation = -1
        self._answer = False

    def __call__(self) -> bool:
        graph = self._graph
        generation = graph.generation
        if generation != self._generation:
            self._answer = graph.all_on_host(SUBSCRIPTION, self._topic, self._host)
            self._generation = generation  # read before asking: a later change asks again
        return self._answer


class _HeldByCaller(Flusher):
    """A flusher that never runs: the publisher's caller sends the batch."""

    def due(self, batch: object) -> bool:
        """Keep the batch (the caller flushes it)."""
        del batch
        return True
