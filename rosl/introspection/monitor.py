"""The loops behind ``topic hz``, ``topic bw`` and ``topic delay`` (yielding report texts)."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from rosl.introspection import rates
from rosl.introspection.echo import compile_filter, run_filter, unpublished_warning
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
            yield unpublished_warning(topic)


def close_names(session: Session, topics: list[str]) -> list[str]:
    """One stderr hint per unpublished topic with a published name close to it.

    ros2 waits silently for a misspelt topic; rosl keeps waiting too, but says what it may mean.
    """
    from rosl.idl.names import did_you_mean

    known = set(session.graph().topics())
    hints = []
    for topic in topics:
        close = "" if topic in known else did_you_mean(topic, known)
        if close:
            hints.append(f"no topic {topic} yet{close}; waiting for it")
    return hints


def _wait_published(session: Session, topic: str) -> bool:
    """Wait (until Ctrl-C or the bus closes) for someone to use ``topic``, as ros2 blocks."""
    participant = session.participant
    while topic not in participant.graph.topics():
        if participant.closed:
            return False
        participant.poll(0.1)
    return True


def _decoder(session: Session, topic: str, expr: str) -> Any:
    from rosl.idl.registry import get_message_class, store

    check = compile_filter(expr)
    if not _wait_published(session, topic):
        raise IntrospectionError(f"--filter needs the type of {topic}, which is not published yet")
    type_name = session.participant.graph.topics()[topic][0]
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
    if not _wait_published(session, topic):
        return
    yield f"Subscribed to [{topic}]"
    last = time.monotonic()
    while not participant.closed:
        participant.poll(0.1)
        if time.monotonic() - last >= 1.0:
            last = time.monotonic()
            text = rates.bw_text(tap.window, time.time_ns())
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

    from rosl.node.qos import qos_profile_sensor_data

    node = session.node()
    node.create_subscription(msg_type, topic, on_message, qos_profile_sensor_data)
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    last = time.monotonic()
    while rosl.ok():
        executor.spin_once(timeout_sec=0.1)
        if time.monotonic() - last >= 1.0:
            last = time.monotonic()
            yield rates.delay_text(delays) or "no new messages"
