"""Subscriptions: queue deliveries for the executor; check the type hash, decode, call back.

Deliveries wait in a queue as deep as the QoS history (keep-last: the oldest goes when it is
full, counted as ``dropped``); the executor that runs the node takes them one at a time.

A message whose type differs from the subscription's is dropped undecoded and reported once
(never mis-decoded); so is one from a publisher whose definition of the same type name differs
(discovery carries each endpoint's definition digest: an edited .msg file while old nodes
run). Transient-local subscriptions ask publishers for their history when created. Callbacks
taking two arguments also get the message info (timestamps, sequence).
"""

from __future__ import annotations

import inspect
import time
from collections import deque
from dataclasses import dataclass, field
from functools import partial
from operator import itemgetter
from typing import TYPE_CHECKING, Any

from rosl.bus.header import Flags, Kind, topic_hash, type_hash
from rosl.bus.wire import Delivery
from rosl.graph.records import LOST_FROM, PUBLISHER, SUBSCRIPTION, EndpointRecord, gid
from rosl.idl import registry
from rosl.idl.errors import InterfaceError
from rosl.node.callback_groups import Queued, held_here, holding
from rosl.node.qos import HistoryPolicy, ReliabilityPolicy
from rosl.node.qos_compatibility import compatible

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.idl.messages import Message
    from rosl.node.node import Node
    from rosl.node.qos import QoSProfile


_REPLAY, _DATA = int(Kind.REPLAY), int(Kind.DATA)  # plain ints compare faster than enums
_monotonic_ns = time.monotonic_ns
_KIND_OF = itemgetter(Delivery._fields.index("kind"))  # (read in C, per message)
_LOCKSTEP = int(Flags.LOCKSTEP)
LOSS_REPORT_EVERY_NS = 5_000_000_000
KEEP_ALL_LIMIT = 1 << 16  # deliveries a keep-all subscription holds before dropping the oldest
MAX_PEERS = 4096  # publishers a subscription remembers what the graph said of
HISTORY_ASKED_AGAIN_S = 1.0  # a late transient-local subscription asks for history again
MAX_LOSS_SOURCES = 16  # publishers whose loss a subscription's record names (the worst first)


def queue_depth(qos: QoSProfile) -> int:
    """How many deliveries wait for the callback: the history depth (keep-all: a bound)."""
    if qos.history is HistoryPolicy.KEEP_ALL:
        return KEEP_ALL_LIMIT
    return max(1, qos.depth)


def _int(value: object) -> int:
    return value if isinstance(value, int) and value > 0 else 0


def _wants_info(callback: Callable[..., Any]) -> bool:
    try:
        params = [
            p
            for p in inspect.signature(callback).parameters.values()
            if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) and p.default is p.empty
        ]
    except (TypeError, ValueError):
        return False
    return len(params) >= 2


@dataclass(slots=True)
class _Peer:
    """One publisher as a subscription sees it."""

    agrees: bool | None  # same definition of the type; None while discovery has not told
    generation: int  # the graph's generation when that was decided
    takes: bool = True  # its QoS matches this subscription's (see qos_compatibility)
    lifespan_ns: int = 0  # its messages are not delivered once older than this (0: never)
    plain: bool = field(init=False)  # its messages are all taken, with no check (the usual)

    def __post_init__(self) -> None:
        self.plain = self.agrees is True and self.takes and not self.lifespan_ns


class Subscription(Queued):
    """Receives one topic's messages (rclpy.subscription.Subscription)."""

    def __init__(
        self,
        node: Node,
        msg_type: type[Message],
        topic: str,
        callback: Callable[..., Any],
        qos: QoSProfile,
        raw: bool = False,
    ) -> None:
        self.node = node
        self.msg_type = msg_type
        self.topic = topic
        self.callback = callback
        self.qos_profile = qos
        self.raw = raw
        self.type_name = msg_type.__msgtype__
        participant = node.participant
        self.endpoint = participant.next_endpoint()
        self._sender = participant.sender
        self._topic_hash = topic_hash(topic)
        self._type_hash = type_hash(self.type_name)
        self._with_info = _wants_info(callback)
        self._store = registry.store()
        self._decode: Callable[[Any], Any] = self._first_decode  # (the type's decoder, made then)
        self.digest = registry.digest(self.type_name)
        self._peers: dict[tuple[int, int], _Peer] = {}  # by (process, endpoint)
        self._graph = participant.graph
        self._streams = participant.reader.streams  # sequence bookkeeping per publisher
        self._lost_told = 0  # the loss already reported in the log
        self.log_loss = True  # False for tools that report loss in their own words (echo)
        # False for tools that refuse another type themselves (echo): they call warn_mismatch
        self.log_mismatch = True
        self.mismatched_from: tuple[int, int] | None = None  # the last such publisher
        self._lost_told_at = 0  # its receive time (ns)
        self._replayed: deque[tuple[int, int, int]] = deque(maxlen=4096)
        self._depth = queue_depth(qos)
        self._queue_in(deque(maxlen=self._depth))
        self._keeps_history = qos.keeps_history
        self._what = topic
        self.received = 0
        self.dropped = 0  # deliveries pushed out of a full queue (the callback fell behind)
        self.mismatched = 0
        self.undecodable = 0
        self.incompatible = 0  # messages of publishers whose QoS does not match (dropped)
        self.expired = 0  # messages older than their publisher's lifespan (dropped)
        self._words = qos.words(subscription=True)
        # reliable: a publisher on this host waits, briefly, before its shared memory drops
        # messages we have not read yet (see rosl.bus.shm_ring)
        self.holding = qos.reliability in (
            ReliabilityPolicy.RELIABLE,
            ReliabilityPolicy.BEST_AVAILABLE,
        )
        # for the deadline and liveliness (see qos_watch): arrival times on the monotonic clock
        self.last_arrival_ns: int | None = None
        self.peer_seen: dict[tuple[int, int], int] | None = None  # per publisher, when tracked
        self._warned: set[int] = set()
        self.destroyed = False
        participant.listen(self._topic_hash, self)
        if qos.keeps_history:
            self._request_history()

    @property
    def topic_name(self) -> str:
        """The fully qualified topic name."""
        return self.topic

    def _request_history(self) -> None:
        # asked again a second later: the ask is one datagram, and nothing else would repair
        # its loss (a replay that comes twice is taken once: see deliver)
        self.node.participant.discovery.send(
            {
                "op": "replay",
                "topic": self.topic,
                "target": [f"{self._sender:016x}", self.endpoint],
            },
            again_after=HISTORY_ASKED_AGAIN_S,
        )

    def deliver(self, delivery: Delivery) -> None:
        """Queue one delivery for this topic (on the polling thread)."""
        if self.destroyed:
            return
        kind = delivery.kind
        if kind != _DATA:
            if kind != _REPLAY:
                return
            address = delivery.address
            if address is None or address[0] != self._sender or address[1] != self.endpoint:
                return  # history asked for by another subscription
            if (delivery.sender, delivery.endpoint, delivery.seq) in self._replayed:
                return  # had already (the history was asked for twice)
        now = self.last_arrival_ns = _monotonic_ns()
        if self.peer_seen is not None:
            self._seen(delivery, now)
        queue = self._queue
        if len(queue) == queue.maxlen:
            self.dropped += 1
        queue.append(delivery)

    def deliver_all(self, deliveries: list[Delivery]) -> None:
        """Queue a poll's deliveries for this topic at once: what :meth:`deliver` of each does."""
        count = len(deliveries)
        if self.destroyed or list(map(_KIND_OF, deliveries)).count(_DATA) != count:
            for delivery in deliveries:  # (replays, or nothing: one at a time)
                self.deliver(delivery)
            return
        now = self.last_arrival_ns = _monotonic_ns()
        if self.peer_seen is not None:
            for delivery in deliveries:
                self._seen(delivery, now)
        queue = self._queue
        pushed_out = len(queue) + count - self._depth  # (the oldest go, new ones too if many)
        if pushed_out > 0:
            self.dropped += pushed_out
        queue.extend(deliveries)

    def _seen(self, delivery: Delivery, now_ns: int) -> None:
        seen = self.peer_seen
        if seen is not None:
            if len(seen) >= MAX_PEERS:
                seen.clear()
            seen[(delivery.sender, delivery.endpoint)] = now_ns

    def drain(self, wait: float = 0.0) -> None:
        """Run the callback for every delivery queued now, on this thread.

        For a blocking wait of rosl's own that needs what already arrived (a TF lookup with a
        timeout, an action's feedback before its result) while no executor may be spinning.
        The callbacks run under the subscription's callback group as an executor's would: at
        once in a callback of that group waiting on this thread, else with the group taken
        here. While another thread runs a callback of the group (a mutually exclusive one),
        this waits up to ``wait`` seconds for it to end, then leaves the deliveries to the
        executor that runs the group.
        """
        group = self.callback_group
        if group is None or held_here(group):
            self._run_queued()
            return
        deadline = time.monotonic() + wait
        while True:  # (a wake-up without work would make a waiting caller look again at once)
            if not self._ready():
                return
            if group.beginning_execution(self):
                break
            if time.monotonic() >= deadline:
                return
            time.sleep(0.002)
        try:
            with holding(group):
                self._run_queued()
        finally:
            group.ending_execution(self)
            self.node.context.wake_executors()  # one may have passed over the busy group

    def _run_queued(self) -> None:
        while not self.destroyed and self._ready():
            work = self._take()
            if work is not None:
                work()

    def _take(self) -> Callable[[], Any] | None:
        """Take the oldest queued delivery: the call of the callback with its message."""
        try:
            delivery = self._queue.popleft()
        except IndexError:
            return None  # another thread took it
        kind, sender, endpoint, seq, _, type_, stamp, received, payload, _, flags = delivery
        if flags & _LOCKSTEP:
            answerer = self.node.participant.answerer
            if answerer is not None:
                answerer.handled(delivery)
        if self.destroyed:
            return None
        if kind == _REPLAY:
            replayed = (sender, endpoint, seq)
            if replayed in self._replayed:
                return None
            self._replayed.append(replayed)
        if type_ != self._type_hash:
            self._mismatch(delivery)
            return None
        key = (sender, endpoint)
        peer = self._peers.get(key)
        if (peer is None or not peer.plain) and not self._admits(delivery, key, peer):
            return None
        if kind == _DATA:
            if self._keeps_history:
                self._replayed.append((sender, endpoint, seq))
            stats = self._streams.get(key)
            if stats is not None and stats.lost and received >= self._lost_told_at:
                self._tell_loss(delivery)
        if self.raw:
            message: Any = _as_bytes(payload)
        else:
            try:
                message = self._decode(payload)
            except InterfaceError as err:
                self.undecodable += 1
                if self.undecodable == 1:
                    self.node.get_logger().warn(f"dropped a message on {self.topic}: {err}")
                return None
        self.received += 1
        if self._with_info:
            info = {
                "source_timestamp": stamp,
                "received_timestamp": received,
                "publication_sequence_number": seq,
                "reception_sequence_number": self.received,
                "publisher_gid": (sender, endpoint),
            }
            return partial(self.callback, message, info)
        return partial(self.callback, message)

    def _admits(self, delivery: Delivery, key: tuple[int, int], peer: _Peer | None) -> bool:
        """Whether a message of a publisher that is not plain is taken (counts what is not)."""
        if peer is None or (peer.agrees is None and peer.generation != self._graph.generation):
            if len(self._peers) >= MAX_PEERS:
                self._peers.clear()  # a cache of the graph: strangers' ids must not grow it
            peer = self._peers[key] = self._meet(delivery)
        if peer.agrees is False:
            self.mismatched += 1
            return False
        if not peer.takes:
            self.incompatible += 1
            return False
        if peer.lifespan_ns and time.time_ns() - delivery.stamp > peer.lifespan_ns:
            self.expired += 1
            return False
        return True

    def _first_decode(self, payload: Any) -> Any:
        """Decode the first message: make the type's decoder (see ``Store.decoder``) first."""
        self._decode = self._store.decoder(self.type_name)
        return self._decode(payload)

    def never_hold(self) -> None:
        """Never keep a shared-memory publisher waiting (a tool that views what it takes)."""
        self.holding = False
        self.node.participant.rehold()

    def _mismatch(self, delivery: Delivery) -> None:
        self.mismatched += 1
        self.mismatched_from = (delivery.sender, delivery.endpoint)
        if self.log_mismatch:
            self.warn_mismatch(delivery.sender, delivery.endpoint, named=False)

    def warn_mismatch(self, sender: int, endpoint: int, named: bool = True) -> bool:
        """Warn (once per process) of a publisher whose messages are of another type.

        With ``named``, only once the graph names the publisher (False: not yet, ask again).
        """
        if sender in self._warned or len(self._warned) >= MAX_PEERS:
            return True
        found = self._graph.sender(sender, endpoint, PUBLISHER, self.topic)
        if named and not found:
            return False
        self._warned.add(sender)
        who = f" from {found[0].fqn} ({found[1].type})" if found else ""
        self.node.get_logger().warn(
            f"subscription on {self.topic} expects {self.type_name} but got a message of another "
            f"type{who}; dropped without decoding (publisher and subscriber types must match)"
        )
        return True

    def _tell_loss(self, delivery: Delivery) -> None:
        """Log messages lost on this topic since the last report (at most every few seconds)."""
        lost = self.lost
        self._lost_told_at = delivery.received + LOSS_REPORT_EVERY_NS
        if lost <= self._lost_told or not self.log_loss:
            return
        self.node.get_logger().warn(
            f"lost {lost - self._lost_told} message(s) on {self.topic} (sequence gaps: the "
            "process fell behind the publisher or its socket buffer overflowed)"
        )
        self._lost_told = lost

    def _meet(self, delivery: Delivery) -> _Peer:
        """What this subscription knows of a publisher, from the graph (once per change).

        Whether it reads the type as this process does: a publisher discovery has not
        announced yet is delivered, and asked about again when the graph changes.
        """
        generation = self._graph.generation
        found = self._graph.sender(delivery.sender, delivery.endpoint, PUBLISHER, self.topic)
        if found is None:
            return _Peer(None, generation)
        node, endpoint = found
        agrees = not endpoint.digest or not self.digest or endpoint.digest == self.digest
        if not agrees:
            self.node.get_logger().warn(
                f"subscription on {self.topic} expects {self.type_name} as this process's "
                f".msg files define it, but {node.fqn} publishes another definition of it "
                "(one of the two .msg files changed); dropped without decoding"
            )
        qos = endpoint.qos
        return _Peer(agrees, generation, compatible(qos, self._words), _int(qos.get("lifespan")))

    @property
    def lost(self) -> int:
        """Messages lost on this topic (sequence gaps seen by this process)."""
        return self.node.participant.reader.lost(self._topic_hash)

    def lost_by_publisher(self) -> dict[tuple[int, int], int]:
        """Messages lost on this topic per publisher (process, endpoint), where any were."""
        return self.node.participant.reader.lost_by_publisher(self._topic_hash)

    def record(self) -> EndpointRecord:
        """This subscription as discovery announces it (with the loss of the worst publishers)."""
        stats = {"received": self.received, "lost": self.lost, "dropped": self.dropped,
                 "mismatched": self.mismatched, "incompatible": self.incompatible,
                 "expired": self.expired}  # fmt: skip
        worst = sorted(self.lost_by_publisher().items(), key=lambda item: -item[1])
        for (process, endpoint), lost in worst[:MAX_LOSS_SOURCES]:
            stats[f"{LOST_FROM}{gid(process, endpoint)}"] = lost
        return EndpointRecord(
            SUBSCRIPTION, self.topic, self.type_name, self.endpoint, self._words, stats,
            self.digest,
        )  # fmt: skip

    def close(self) -> None:
        """Stop receiving."""
        self.destroyed = True
        self.node.participant.unlisten(self._topic_hash, self)

    def destroy(self) -> None:
        """Stop receiving (rclpy: node.destroy_subscription)."""
        self.node.destroy_subscription(self)


def _as_bytes(payload: Any) -> bytes:
    """A raw message's bytes, copied only when they are not a whole bytes object already.

    The Zenoh transport's payloads view all of one (no copy of a large message on the polling
    thread); the multicast bus's view into a receive buffer, which is copied.
    """
    if type(payload) is memoryview:
        whole = payload.obj
        if type(whole) is bytes and len(whole) == payload.nbytes:
            return whole
    return bytes(payload)
