"""QoS events of one node: incompatible QoS, deadlines, liveliness and message loss.

A steady internal timer (every 0.5 s, sooner when a deadline or lease needs it) looks at the
node's publishers and subscriptions and calls the callbacks given in ``event_callbacks``, on
the executor that runs the node, as rclpy's event handlers do:

* incompatible QoS: when the graph shows a new endpoint on the topic whose QoS does not match
  (:mod:`rosl.node.qos_compatibility`), on both sides; without a callback, rclpy's warning;
* deadline: a period of the entity's deadline without a message (counted from the first one);
* liveliness: a subscription's matched publishers becoming alive or not (an automatic one is
  alive while its process is in the graph; a manual-by-topic one while it publishes or asserts
  within its lease); a manual-by-topic publisher that let its lease run out loses liveliness;
* message lost: sequence gaps the bus counted on the subscription's topic;
* matched (Jazzy): the compatible endpoints of the other side, as they come and go;
  incompatible type (Jazzy): endpoints on the topic with another message type.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.graph.records import PUBLISHER, SUBSCRIPTION
from rosl.node.clock import Clock, ClockType
from rosl.node.qos import MANUAL, duration_ns, qos_policy_name_from_kind
from rosl.node.qos_compatibility import Mismatch, mismatches
from rosl.node.qos_events import (
    IncompatibleTypeInfo,
    QoSLivelinessChangedInfo,
    QoSLivelinessLostInfo,
    QoSMessageLostInfo,
    QoSOfferedDeadlineMissedInfo,
    QoSRequestedDeadlineMissedInfo,
    QoSRequestedIncompatibleQoSInfo,
    QoSSubscriptionMatchedInfo,
)

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.graph.cache import GraphCache
    from rosl.node.node import Node
    from rosl.node.publisher import Publisher
    from rosl.node.qos_events import PublisherEventCallbacks, SubscriptionEventCallbacks
    from rosl.node.subscription import Subscription
    from rosl.node.timer import Timer

PERIOD_NS = 500_000_000  # how often the node looks when nothing needs it sooner
MIN_PERIOD_NS = 10_000_000


@dataclass(slots=True)
class Deadline:
    """Counts the deadline periods that passed without activity (from the first activity)."""

    period_ns: int
    due_ns: int = 0
    total: int = 0

    def missed(self, last_ns: int | None, now_ns: int) -> int:
        """How many more periods were missed by ``now_ns``, the last activity at ``last_ns``."""
        if last_ns is None or not self.period_ns:
            return 0
        self.due_ns = max(self.due_ns, last_ns + self.period_ns)
        if now_ns < self.due_ns:
            return 0
        count = (now_ns - self.due_ns) // self.period_ns + 1
        self.due_ns += count * self.period_ns
        self.total += count
        return count


@dataclass(slots=True)
class Incompatible:
    """The endpoints on a topic found not to match, and the count already told."""

    seen: set[tuple[int, int]] = field(default_factory=set)
    total: int = 0
    last: Mismatch | None = None


@dataclass(slots=True)
class _Peer:
    """A matched publisher as a subscription's liveliness sees it."""

    manual: bool
    lease_ns: int
    alive: bool
    not_alive: bool = False  # counted not alive (a manual one whose lease ran out)


@dataclass(slots=True)
class _Liveliness:
    peers: dict[tuple[int, int], _Peer] = field(default_factory=dict)
    alive: int = 0
    not_alive: int = 0


class _Watched:
    """One publisher or subscription with its callbacks and event state."""

    def __init__(self, entity: Publisher | Subscription, callbacks: Any, kind: str) -> None:
        self.entity = entity
        self.callbacks = callbacks
        self.kind = kind  # PUBLISHER or SUBSCRIPTION
        self.words = entity.qos_profile.words(kind == SUBSCRIPTION)
        self.incompatible = Incompatible()
        self.wrong_types: set[tuple[int, int]] = set()  # endpoints of another type, told
        self.wrong_type_total = 0
        self.matched: set[tuple[int, int]] = set()
        self.matched_total = 0
        self.deadline = Deadline(duration_ns(entity.qos_profile.deadline))
        self.lease_ns = duration_ns(entity.qos_profile.liveliness_lease_duration)
        self.lost_told = 0
        self.lost = 0  # liveliness lost (publisher)
        self.liveliness = _Liveliness()

    def callback(self, name: str) -> Callable[[Any], None] | None:
        return getattr(self.callbacks, name, None) if self.callbacks is not None else None

    @property
    def defaults(self) -> bool:
        return self.callbacks is None or bool(self.callbacks.use_default_callbacks)


class QoSWatch:
    """Raises the QoS events of one node's publishers and subscriptions.

    Graph changes trigger an internal guard condition (incompatible QoS, publishers coming and
    going); entities with a deadline, a lease or timing callbacks add an internal timer.
    """

    def __init__(self, node: Node) -> None:
        self.node = node
        self.watched: list[_Watched] = []
        self.generation = -1
        self.guard = node.create_guard_condition(self.check)
        self.guard._internal = True
        self.timer: Timer | None = None
        node.participant.graph.listeners.append(self._graph_changed)

    def _graph_changed(self) -> bool:
        if self.node._destroyed:
            return False  # no longer told
        self.guard.trigger()
        return True

    def add_publisher(
        self, publisher: Publisher, callbacks: PublisherEventCallbacks | None
    ) -> None:
        """Watch a publisher (its events go to ``callbacks``)."""
        watched = _Watched(publisher, callbacks, PUBLISHER)
        manual = publisher.qos_profile.liveliness in MANUAL
        self._add(watched, watched.deadline.period_ns, watched.lease_ns if manual else 0)

    def add_subscription(
        self, subscription: Subscription, callbacks: SubscriptionEventCallbacks | None
    ) -> None:
        """Watch a subscription (its events go to ``callbacks``)."""
        watched = _Watched(subscription, callbacks, SUBSCRIPTION)
        timed = 0
        if watched.callback("liveliness") is not None:
            subscription.peer_seen = {}
            timed = PERIOD_NS
        if watched.callback("message_lost") is not None:
            timed = PERIOD_NS
        self._add(watched, watched.deadline.period_ns, timed)

    def _add(self, watched: _Watched, *periods_ns: int) -> None:
        self.watched.append(watched)
        self.generation = -1  # look at the graph for it at once
        self.guard.trigger()
        periods = [p for p in periods_ns if p]
        if not periods:
            return
        wanted = max(MIN_PERIOD_NS, min(PERIOD_NS, min(periods) // 4))
        if self.timer is None:
            clock = Clock(clock_type=ClockType.STEADY_TIME)
            self.timer = self.node.create_timer(wanted / 1e9, self.check, clock=clock)
            self.timer._internal = True
        elif wanted < self.timer.timer_period_ns:
            self.timer.timer_period_ns = wanted

    def check(self) -> None:
        """Look at every watched entity and call the callbacks of what happened."""
        self.watched = [w for w in self.watched if not w.entity.destroyed]
        graph = self.node.participant.graph
        generation = graph.generation
        if generation != self.generation:
            self.generation = generation
            for watched in self.watched:
                self._graph_events(watched, graph)
        now = time.monotonic_ns()  # what it is compared with is of the same (local) clock
        for watched in self.watched:
            if watched.kind == PUBLISHER:
                self._publisher_timing(watched, now)
            else:
                self._subscription_timing(watched, now, graph)

    # --- what the graph shows: incompatible QoS or type, matches ----------------------------

    def _graph_events(self, watched: _Watched, graph: GraphCache) -> None:
        entity = watched.entity
        other = SUBSCRIPTION if watched.kind == PUBLISHER else PUBLISHER
        state = watched.incompatible
        change = wrong_types = 0
        matched: set[tuple[int, int]] = set()
        for node, endpoint in graph.endpoints(other, entity.topic):
            key = (node.process, endpoint.endpoint)
            if endpoint.type != entity.type_name:
                if key not in watched.wrong_types:
                    watched.wrong_types.add(key)
                    wrong_types += 1
                continue
            if watched.kind == PUBLISHER:
                found = mismatches(watched.words, endpoint.qos)
            else:
                found = mismatches(endpoint.qos, watched.words)
            if not found:
                matched.add(key)
            elif key not in state.seen:
                state.seen.add(key)
                state.last = found[-1]
                change += 1
        if change and state.last is not None:
            state.total += change
            self._tell_incompatible(
                watched, QoSRequestedIncompatibleQoSInfo(state.total, change, state.last.kind)
            )
        callback = watched.callback("incompatible_type")
        watched.wrong_type_total += wrong_types
        if wrong_types and callback is not None:
            callback(IncompatibleTypeInfo(watched.wrong_type_total, wrong_types))
        self._tell_matched(watched, matched)

    def _tell_matched(self, watched: _Watched, matched: set[tuple[int, int]]) -> None:
        before = watched.matched
        added = len(matched - before)
        if matched == before:
            return
        watched.matched = matched
        watched.matched_total += added
        callback = watched.callback("matched")
        if callback is not None:
            callback(QoSSubscriptionMatchedInfo(
                watched.matched_total, added, len(matched), len(matched) - len(before)
            ))  # fmt: skip

    def _tell_incompatible(self, watched: _Watched, info: QoSRequestedIncompatibleQoSInfo) -> None:
        callback = watched.callback("incompatible_qos")
        if callback is not None:
            callback(info)
        elif watched.defaults:
            self._warn_incompatible(watched, info)

    def _warn_incompatible(self, watched: _Watched, info: QoSRequestedIncompatibleQoSInfo) -> None:
        topic = watched.entity.topic
        policy = qos_policy_name_from_kind(info.last_policy_kind)
        if watched.kind == PUBLISHER:
            text = (
                f"New subscription discovered on topic '{topic}', requesting incompatible QoS. "
                f"No messages will be sent to it. Last incompatible policy: {policy}"
            )
        else:
            text = (
                f"New publisher discovered on topic '{topic}', offering incompatible QoS. "
                f"No messages will be received from it. Last incompatible policy: {policy}"
            )
        self.node.get_logger().warn(text)

    # --- deadline, liveliness, loss ----------------------------------------------------------

    def _publisher_timing(self, watched: _Watched, now: int) -> None:
        publisher: Any = watched.entity
        missed = watched.deadline.missed(publisher.last_published_ns, now)
        callback = watched.callback("deadline")
        if missed and callback is not None:
            callback(QoSOfferedDeadlineMissedInfo(watched.deadline.total, missed))
        manual = publisher.qos_profile.liveliness in MANUAL
        if not manual or not watched.lease_ns:
            return
        lapsed = now - publisher.last_asserted_ns > watched.lease_ns
        if lapsed and publisher.alive:
            publisher.alive = False
            watched.lost += 1
            callback = watched.callback("liveliness")
            if callback is not None:
                callback(QoSLivelinessLostInfo(watched.lost, 1))

    def _subscription_timing(self, watched: _Watched, now: int, graph: GraphCache) -> None:
        subscription: Any = watched.entity
        missed = watched.deadline.missed(subscription.last_arrival_ns, now)
        callback = watched.callback("deadline")
        if missed and callback is not None:
            callback(QoSRequestedDeadlineMissedInfo(watched.deadline.total, missed))
        callback = watched.callback("message_lost")
        if callback is not None:
            lost = subscription.lost
            if lost > watched.lost_told:
                change, watched.lost_told = lost - watched.lost_told, lost
                callback(QoSMessageLostInfo(lost, change))
        callback = watched.callback("liveliness")
        if callback is not None:
            self._liveliness(watched, now, graph, callback)

    def _liveliness(
        self, watched: _Watched, now: int, graph: GraphCache, callback: Callable[[Any], None]
    ) -> None:
        subscription: Any = watched.entity
        state = watched.liveliness
        before = (state.alive, state.not_alive)
        present = set()
        for node, endpoint in graph.endpoints(PUBLISHER, subscription.topic):
            key = (node.process, endpoint.endpoint)
            if endpoint.type != subscription.type_name or mismatches(endpoint.qos, watched.words):
                continue
            present.add(key)
            if key not in state.peers:
                manual = endpoint.qos.get("liveliness") in ("MANUAL_BY_NODE", "MANUAL_BY_TOPIC")
                lease = int(endpoint.qos.get("liveliness_lease_duration", 0) or 0)
                state.peers[key] = _Peer(manual, lease, alive=not manual)
                if not manual:
                    state.alive += 1
        asserted = self.node.participant.asserted
        seen = subscription.peer_seen or {}
        for key, peer in list(state.peers.items()):
            if key not in present:
                del state.peers[key]
                state.alive -= peer.alive
                state.not_alive -= peer.not_alive
                continue
            if not peer.manual:
                continue
            last = max(asserted.get(key, 0), seen.get(key, 0))
            fresh = last > 0 and (not peer.lease_ns or now - last <= peer.lease_ns)
            if fresh and not peer.alive:
                state.not_alive -= peer.not_alive
                peer.alive, peer.not_alive = True, False
                state.alive += 1
            elif not fresh and peer.alive:
                peer.alive, peer.not_alive = False, True
                state.alive -= 1
                state.not_alive += 1
        if (state.alive, state.not_alive) != before:
            callback(
                QoSLivelinessChangedInfo(
                    state.alive, state.not_alive, state.alive - before[0],
                    state.not_alive - before[1],
                )
            )  # fmt: skip


def watch(node: Node) -> QoSWatch:
    """The node's QoS watch (created with its first publisher or subscription)."""
    if node._qos_watch is None:
        node._qos_watch = QoSWatch(node)
    return node._qos_watch
