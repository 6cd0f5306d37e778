"""The loops behind ``topic hz``, ``topic bw`` and ``topic delay`` (yielding report texts)."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from rosl.introspection import rates
from rosl.introspection.echo import compile_filter, run_filter
from rosl.introspection.errors import IntrospectionError

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.bus.wire import Delivery
    from rosl.introspection.session import Session

REPORT_NS = 1_000_000_000


def _warn_unpublished(session: Session, topics: list[str]) -> Iterator[str]:
    known = session.graph().topics()
    for topic in topics:
        if topic not in known:
            yield f"WARNING: topic [{topic}] does not appear to be published yet"


def _decoder(session: Session, topic: str, expr: str) -> Any:
    from rosl.idl.registry import get_message_class, store

    check = compile_filter(expr)
    types = session.graph().topics().get(topic)
    if not types:
        raise IntrospectionError(f"--filter needs the type of {topic}, which is not published yet")
    type_name = types[0]
    get_message_class(type_name)
    serde = store()

    def accept(delivery: Delivery) -> bool:
        message = serde.deserialize(delivery.payload, type_name)
        return run_filter(check, expr, message)

    return accept


def hz(
    session: Session, topics: list[str], window: int, filter_expr: str | None = None
) -> Iterator[str]:
    """Yield ros2's rate report(s) about once a second, until Ctrl-C."""
    yield from _warn_unpublished(session, topics)
    participant = session.participant
    taps = {}
    for topic in topics:
        accept = _decoder(session, topic, filter_expr) if filter_expr else None
        tap = rates.Tap(topic, window, accept)
        participant.listen(tap.hash, tap)
        taps[topic] = tap
        if len(topics) > 1:
            yield f"Subscribed to [{topic}]"
    last_table = time.monotonic()
    while not participant.closed:
        participant.poll(0.1)
        if len(topics) == 1:
            window_ = taps[topics[0]].window
            if rates.due(window_, REPORT_NS):
                text = rates.hz_text(window_)
                if text:
                    yield text
        elif time.monotonic() - last_table >= 1.0:
            last_table = time.monotonic()
            yield rates.hz_table({t: tap.window for t, tap in taps.items()}) or "no new messages"


def bw(session: Session, topic: str, window: int) -> Iterator[str]:
    """Yield ros2's bandwidth report about once a second, until Ctrl-C."""
    yield from _warn_unpublished(session, [topic])
    participant = session.participant
    tap = rates.Tap(topic, window)
    participant.listen(tap.hash, tap)
    yield f"Subscribed to [{topic}]"
    last = time.monotonic()
    while not participant.closed:
        participant.poll(0.1)
        if time.monotonic() - last >= 1.0:
            last = time.monotonic()
            text = rates.bw_text(tap.window)
            if text:
                yield text


def delay(session: Session, topic: str, window: int) -> Iterator[str]:
    """Yield ros2's delay report (receive time minus header.stamp) about once a second."""
    import rosl
    from rosl.idl.registry import get_message_class

    types = session.graph().topics().get(topic)
    if not types:
        raise IntrospectionError(f"Unknown topic '{topic}': delay needs a topic being published")
    msg_type = get_message_class(types[0])
    if not any(n == "header" for n in msg_type._fields):
        raise IntrospectionError(f"msg does not have header: {types[0]} on {topic}")
    delays = rates.Delays(window)

    def on_message(message: Any, info: dict[str, Any]) -> None:
        stamp = rates.header_stamp_ns(message)
        if stamp is not None:
            delays.add(info["received_timestamp"], stamp)

    node = session.node()
    node.create_subscription(msg_type, topic, on_message, 10)
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    last = time.monotonic()
    while rosl.ok():
        executor.spin_once(timeout_sec=0.1)
        if time.monotonic() - last >= 1.0:
            last = time.monotonic()
            yield rates.delay_text(delays) or "no new messages"
