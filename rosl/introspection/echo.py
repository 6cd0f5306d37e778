"""``topic echo``: subscribe and render each message as ros2cli does (YAML + ``---``).

Adds what ros2's echo hides: a lost message (a sequence gap) is reported in ros2's own
"A message was lost!!!" form, and history of transient-local publishers (``/tf_static``) is
received because the subscription matches their durability.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosl.graph.records import PUBLISHER
from rosl.idl.base import Message
from rosl.introspection.errors import IntrospectionError

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.graph.cache import GraphCache
    from rosl.graph.records import EndpointRecord, NodeRecord
    from rosl.introspection.session import Session
    from rosl.node.qos import QoSProfile

DEFAULT_TRUNCATE = 128


@dataclass(slots=True)
class EchoOptions:
    """How ``topic echo`` renders (the ros2 flags)."""

    once: bool = False
    field: str | None = None
    csv: bool = False
    no_arr: bool = False
    no_str: bool = False
    flow_style: bool = False
    truncate_length: int | None = DEFAULT_TRUNCATE
    filter_expr: str | None = None
    timeout: float | None = None
    include_info: bool = False
    count: int | None = None
    qos: QoSProfile | None = None  # None: matched to the publishers, as ros2 does
    lost_messages: bool = True
    raw: bool = False


NO_TYPE = "Could not determine the type for the passed topic"


def unpublished_warning(topic: str) -> str:
    """ros2's line (on stdout) for a topic nobody publishes yet."""
    return f"WARNING: topic [{topic}] does not appear to be published yet"


def resolve_type(session: Session, topic: str, type_name: str | None) -> str:
    """The type to echo: the given one, else the topic's (which must be known and unique).

    Raises:
        IntrospectionError: ros2's "Could not determine the type for the passed topic" (with
            the closest published name, if any) for an unknown topic and no type.
    """
    from rosl.idl.names import canonical, did_you_mean

    if type_name:
        wanted = canonical(type_name)
        check_published_type(session.graph(), topic, wanted)
        return wanted
    topics = session.graph().topics()
    if topic not in topics:
        raise IntrospectionError(NO_TYPE + did_you_mean(topic, set(topics)))
    if len(topics[topic]) > 1:
        raise IntrospectionError(
            f"Cannot echo topic '{topic}', as it contains more than one type: "
            f"[{', '.join(topics[topic])}]"
        )
    return topics[topic][0]


def check_published_type(graph: GraphCache, topic: str, wanted: str) -> None:
    """Fail when ``topic`` has publishers and none of them publishes ``wanted``.

    A topic nobody publishes yet passes: echo then waits for its first publisher.
    """
    published = sorted({e.type for _, e in graph.endpoints(PUBLISHER, topic)})
    if published and wanted not in published:
        raise IntrospectionError(
            f"Cannot echo topic '{topic}' as {wanted}: it is published as {' and '.join(published)}"
        )


def field_parts(path: str | None) -> list[str]:
    """The names of ``--field a.b.c`` (empty names dropped, as ros2 does).

    Raises:
        IntrospectionError: ros2's "Invalid field value '.'" when no name is left.
    """
    if path is None:
        return []
    parts = [part for part in path.split(".") if part]
    if not parts:
        raise IntrospectionError(f"Invalid field value '{path}'")
    return parts


def _no_field(value: Any, parts: list[str], part: str) -> IntrospectionError:
    """ros2's "Invalid field 'a.b': 'Type' object has no attribute 'b'"."""
    owner = value.__name__ if isinstance(value, type) else type(value).__name__
    return IntrospectionError(
        f"Invalid field '{'.'.join(parts)}': '{owner}' object has no attribute '{part}'"
    )


def check_field(msg_type: type[Message], parts: list[str]) -> None:
    """Refuse, before any message arrives, a ``--field`` naming no field of the type.

    Names past a primitive or an array are left to :func:`select_field`.
    """
    cls: type[Message] = msg_type
    for part in parts:
        if part not in cls._fields:
            raise _no_field(cls, parts, part)
        ftype = cls._field_types[cls._fields.index(part)]
        if ftype.is_primitive or ftype.is_array:
            return
        cls = cls._field_classes[part]


def select_field(message: Any, parts: list[str]) -> Any:
    """Follow ``--field a.b.c`` (as :func:`field_parts` split it) into a message."""
    value = message
    for part in parts:
        if isinstance(value, Message):
            if part not in value._fields:
                raise _no_field(value, parts, part)
            value = getattr(value, part)
            continue
        try:
            value = getattr(value, part)
        except AttributeError as err:  # Python's own words, as ros2 prints them
            raise IntrospectionError(f"Invalid field '{'.'.join(parts)}': {err}") from None
    return value


def matched_qos(
    publishers: list[tuple[NodeRecord, EndpointRecord]],
) -> tuple[QoSProfile, list[str]]:
    """ros2's echo QoS when none is given: reliable/transient-local only if every publisher is.

    Returns:
        The profile (sensor_data's words, with a deeper queue), and ros2's notes (stdout) when
        only some publishers offer the stronger policy.
    """
    from rosl.node.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    qos = QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT)
    notes: list[str] = []
    offered = [e.qos for _, e in publishers]
    for key, strong, weak, policy in (
        ("reliability", "RELIABLE", "BEST_EFFORT", "QoSReliabilityPolicy"),
        ("durability", "TRANSIENT_LOCAL", "VOLATILE", "QoSDurabilityPolicy"),
    ):
        count = sum(1 for words in offered if words.get(key) == strong)
        if offered and count == len(offered):
            chosen = strong
        else:
            chosen = weak
            if count:
                notes.append(
                    f"Some, but not all, publishers are offering {policy}.{strong}. Falling back "
                    f"to {policy}.{weak} as it will connect to all publishers"
                )
        if key == "reliability":
            qos.reliability = ReliabilityPolicy[chosen]
        else:
            qos.durability = DurabilityPolicy[chosen]
    return qos, notes


def compile_filter(expr: str | None) -> Any:
    """Compile ``--filter`` (a Python expression over ``m``)."""
    if not expr:
        return None
    try:
        return compile(expr, "<--filter>", "eval")
    except SyntaxError as err:
        raise IntrospectionError(
            f"--filter '{expr}' is not a Python expression: {err.msg}"
        ) from None


def run_filter(check: Any, expr: str | None, value: Any) -> bool:
    """Evaluate a compiled ``--filter`` on ``m = value``; a failure is the user's error.

    Raises:
        IntrospectionError: the expression raised (one line: expression, error type, text).
    """
    try:
        return bool(eval(check, {"m": value}))
    except Exception as err:  # any error of the user's expression is theirs to fix
        raise IntrospectionError(f"--filter: {expr}: {type(err).__name__}: {err}") from None


def render(value: Any, options: EchoOptions) -> str:
    """One message (or selected field) as echo prints it: YAML and ``---``, or a CSV line."""
    from rosl.idl.yaml_io import (
        dump_yaml,
        message_to_csv,
        message_to_yaml,
        value_to_csv,
        value_to_plain,
    )

    truncate = options.truncate_length
    if isinstance(value, Message):
        if options.csv:  # one line per message, no "---" (as ros2 prints it)
            return message_to_csv(value, truncate_length=truncate, no_arr=options.no_arr,
                                  no_str=options.no_str)  # fmt: skip
        text = message_to_yaml(
            value, truncate_length=truncate, no_arr=options.no_arr, no_str=options.no_str,
            flow_style=options.flow_style,
        )  # fmt: skip
        return text + "---"
    if options.csv:
        return value_to_csv(value, truncate_length=truncate)
    if hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, list):  # items as in a message's YAML (a byte as its character)
        return dump_yaml(value_to_plain(value, truncate_length=truncate)).rstrip("\n") + "\n---"
    return f"{value}\n---"  # a lone primitive prints as Python prints it, as ros2 does


def _texts(value: Any, info: dict[str, Any], options: EchoOptions) -> list[str]:
    """What one received message prints: with ``-i``, its info first (or first in the CSV)."""
    text = render(value, options)
    if not options.include_info:
        return [text]
    if options.csv and isinstance(value, Message):
        scalars = (v for v in info.values() if isinstance(v, (int, float, str)))
        return [",".join(map(str, scalars)) + "," + text]  # ros2's four numbers, then the line
    from rosl.idl.yaml_io import dump_yaml

    return [dump_yaml(info).rstrip("\n") + "\n---", text]


def echo(
    session: Session, topic: str, type_name: str | None, options: EchoOptions
) -> Iterator[str]:
    """Yield each message's text until Ctrl-C, ``--once``, or the timeout.

    Raises:
        IntrospectionError: unknown topic/type, a bad --field/--filter, or nothing arrived
            within ``--timeout``.
    """
    from rosl.idl.registry import get_message_class

    parts = field_parts(options.field)
    node = session.node()  # first: its participant then answers the graph query too
    if type_name is None and topic not in session.graph_knowing(topic).topics():
        yield unpublished_warning(topic)  # then ros2's error, from resolve_type
    resolved = resolve_type(session, topic, type_name)
    msg_type = get_message_class(resolved)
    check_field(msg_type, [] if options.raw else parts)
    check = compile_filter(options.filter_expr)
    qos = options.qos
    if qos is None:
        qos, notes = matched_qos(session.graph().endpoints(PUBLISHER, topic))
        yield from notes
    inbox: list[tuple[Any, dict[str, Any]]] = []
    subscription = node.create_subscription(
        msg_type, topic, lambda m, info: inbox.append((m, info)), qos, raw=options.raw
    )
    subscription.log_loss = False  # echo says "A message was lost!!!" itself, as ros2 does
    # a publisher of another type: refused below in one line, or else warned of (once the
    # graph names it: it may have been heard before discovery told of it)
    subscription.log_mismatch = False
    subscription.never_hold()  # a view never slows what it shows (see rosl.bus.shm_ring)
    import rosl

    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    started = time.monotonic()
    shown = 0
    lost_seen = 0
    while rosl.ok():
        if type_name and not shown:  # a publisher that appears while we wait may not match
            check_published_type(node.participant.graph, topic, resolved)
        stranger = subscription.mismatched_from
        if stranger is not None and subscription.warn_mismatch(*stranger):
            subscription.mismatched_from = None
        executor.spin_once(timeout_sec=0.1)
        lost = subscription.lost
        if lost > lost_seen and options.lost_messages:
            change = lost - lost_seen
            yield (
                f"A message was lost!!!\n\ttotal count change:{change}\n\ttotal count: {lost}\n---"
            )
            lost_seen = lost
        for message, info in inbox:
            value = select_field(message, parts)
            if check is not None and not run_filter(check, options.filter_expr, value):
                continue
            yield from _texts(value, info, options)
            shown += 1
            if options.once or (options.count is not None and shown >= options.count):
                return
        inbox.clear()
        if (
            options.timeout is not None
            and not shown
            and time.monotonic() - started > options.timeout
        ):
            raise IntrospectionError(f"no message on {topic} within {options.timeout} s")
