"""``topic pub``: publish YAML-given values, once, N times, or at a rate.

``header: auto`` stamps each message's header with the current time and ``now`` fills a
builtin_interfaces/Time field, as in ros2. With ``--once`` (or ``--times``) it first waits,
bounded, for matched subscriptions, so a single message is not lost to discovery, and says
how many subscriptions it was sent to.
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosl.graph.records import SUBSCRIPTION
from rosl.idl.errors import FieldError
from rosl.introspection.errors import IntrospectionError

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.idl.base import Message
    from rosl.introspection.session import Session
    from rosl.node.qos import QoSProfile

HEADER = "std_msgs/msg/Header"
TIME = "builtin_interfaces/msg/Time"


@dataclass(slots=True)
class PubOptions:
    """The ros2 ``topic pub`` flags."""

    rate: float = 1.0
    once: bool = False
    times: int = 0
    print_every: int = 1
    wait_matching: int | None = None  # None: 1 with --once/--times, else 0
    max_wait: float = 5.0
    keep_alive: float = 0.1
    qos: QoSProfile | None = None  # None: reliable, volatile, keep last 10


def expand_specials(cls: type[Message], values: Any, now_ns: int) -> Any:
    """Replace ``header: auto`` and ``<time field>: now`` with the current time."""
    if not isinstance(values, dict):
        return values
    out = dict(values)
    for name, ftype in zip(cls._fields, cls._field_types, strict=True):
        if name not in out or ftype.is_primitive or ftype.is_array:
            continue
        stamp = {"sec": now_ns // 1_000_000_000, "nanosec": now_ns % 1_000_000_000}
        if ftype.base == HEADER and out[name] == "auto":
            out[name] = {"stamp": stamp}
        elif ftype.base == TIME and out[name] == "now":
            out[name] = stamp
        else:
            out[name] = expand_specials(cls._field_classes[name], out[name], now_ns)
    return out


def build(cls: type[Message], values: Any) -> Message:
    """A message (or service request) from YAML values, after special-value expansion.

    Shared by ``topic pub`` and ``service call`` so both accept and refuse the same values.

    Raises:
        IntrospectionError: ros2's "Failed to populate field: ..." naming the field and the
            type it expects.
    """
    from rosl.idl.messages import from_dict

    try:
        return from_dict(cls, expand_specials(cls, copy.deepcopy(values), time.time_ns()))
    except FieldError as err:
        raise IntrospectionError(f"Failed to populate field: {err}") from None


def publish(
    session: Session, topic: str, type_name: str, values: Any, options: PubOptions
) -> Iterator[tuple[str, str]]:
    """Publish and yield ('out'|'err', text) lines as ros2 prints them.

    Raises:
        IntrospectionError: bad type or values, or no subscriber within the wait bound.
    """
    import rosl
    from rosl.idl.names import canonical
    from rosl.idl.registry import get_message_class
    from rosl.node.qos import QoSProfile

    msg_type = get_message_class(canonical(type_name))
    first = build(msg_type, values)  # validate before touching the bus
    node = session.node()
    qos = options.qos if options.qos is not None else QoSProfile(depth=10)
    publisher = node.create_publisher(msg_type, topic, qos)
    limited = options.once or options.times > 0
    wait_for = options.wait_matching if options.wait_matching is not None else (1 if limited else 0)
    wanted = msg_type.__msgtype__
    yield from _check_subscription_types(session, node, topic, wanted, must_match=wait_for > 0)
    if wait_for > 0:
        yield from _wait_subscribers(node, topic, wanted, wait_for, options.max_wait)
        if not rosl.ok():  # Ctrl-C while waiting
            return
    yield ("out", "publisher: beginning loop")
    total = 1 if options.once else options.times
    count = 0
    period = 1.0 / options.rate if options.rate > 0 else 0.0
    next_at = time.monotonic()
    while rosl.ok():
        message = first if count == 0 else build(msg_type, values)
        publisher.publish(message)
        count += 1
        if options.print_every and count % options.print_every == 0:
            yield ("out", f"publishing #{count}: {message!r}\n")
        if total and count >= total:
            break
        next_at += period
        while rosl.ok() and time.monotonic() < next_at:
            rosl.spin_once(node, timeout_sec=max(0.0, min(0.1, next_at - time.monotonic())))
    if limited:
        matched, _ = _subscriptions(node, topic, wanted)
        yield ("err", f"sent {count} message(s) to {matched} matched subscription(s) on {topic}")
        end = time.monotonic() + options.keep_alive
        while rosl.ok() and time.monotonic() < end:
            rosl.spin_once(node, timeout_sec=max(0.0, end - time.monotonic()))


def _subscriptions(node: Any, topic: str, wanted: str) -> tuple[int, list[str]]:
    """(subscriptions of ``wanted`` on ``topic`` but our own, other types subscribed there)."""
    own = node.get_fully_qualified_name()
    endpoints = node.participant.graph.endpoints(SUBSCRIPTION, topic)
    matched = sum(1 for n, e in endpoints if e.type == wanted and n.fqn != own)
    return matched, sorted({e.type for _, e in endpoints if e.type != wanted})


def _check_subscription_types(
    session: Session, node: Any, topic: str, wanted: str, *, must_match: bool
) -> Iterator[tuple[str, str]]:
    """Refuse (when waiting for a match) or warn about subscriptions of another type.

    They never receive what we send, so ros2 would wait forever for them to match.
    """
    session.graph(fresh=True)  # the node's view, complete
    matched, others = _subscriptions(node, topic, wanted)
    if not others:
        return
    if must_match and not matched:
        raise IntrospectionError(
            f"Cannot publish {wanted} on {topic}: its subscriptions expect {' and '.join(others)}"
        )
    yield (
        "err",
        f"WARNING: subscriptions on {topic} expecting {' and '.join(others)} will not receive "
        f"these {wanted} messages",
    )


def _wait_subscribers(
    node: Any, topic: str, type_name: str, wanted: int, bound: float
) -> Iterator[tuple[str, str]]:
    graph = node.participant.graph
    deadline = time.monotonic() + bound
    announced = 0.0

    def matched() -> int:
        return _subscriptions(node, topic, type_name)[0]

    while matched() < wanted and node.context.ok():  # Ctrl-C ends the wait at once
        now = time.monotonic()
        if now >= deadline:
            raise IntrospectionError(
                f"Timed out waiting for subscribers: Expected {wanted} subcribers but only got "
                f"{matched()} subscribers (waited {bound:g} s on {topic}; nothing was published)"
            )
        if now - announced >= 1.0:
            yield ("out", f"Waiting for at least {wanted} matching subscription(s)...")
            announced = now
        graph.wait_for(lambda: matched() >= wanted, 0.1)
