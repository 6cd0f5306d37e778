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
    from rosl.introspection.session import Session

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


def resolve_type(session: Session, topic: str, type_name: str | None) -> str:
    """The type to echo: the given one, else the topic's (which must be known and unique)."""
    from rosl.idl.names import canonical, did_you_mean

    if type_name:
        wanted = canonical(type_name)
        check_published_type(session.graph(), topic, wanted)
        return wanted
    topics = session.graph().topics()
    if topic not in topics:
        raise IntrospectionError(
            f"WARNING: topic [{topic}] does not appear to be published yet"
            f"{did_you_mean(topic, set(topics))}; give its type to wait for it: "
            f"rosl topic echo {topic} <pkg/msg/Type>"
        )
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


def select_field(message: Any, path: str | None) -> Any:
    """Follow ``--field a.b.c`` into a message."""
    value = message
    for part in (path or "").split("."):
        if not part:
            continue
        if not isinstance(value, Message) or part not in value._fields:
            fields = ", ".join(value._fields) if isinstance(value, Message) else "(none)"
            raise IntrospectionError(f"Invalid field '{path}': no '{part}' (fields: {fields})")
        value = getattr(value, part)
    return value


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
    from rosl.idl.yaml_io import dump_yaml, message_to_csv, message_to_yaml

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
    if hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, list):
        return dump_yaml([_plain(v, truncate) for v in value]).rstrip("\n") + "\n---"
    return f"{value}\n---"


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


def _plain(value: Any, truncate: int | None) -> Any:
    from rosl.idl.yaml_io import message_to_ordered

    if isinstance(value, Message):
        return message_to_ordered(value, truncate_length=truncate)
    return value


def echo(
    session: Session, topic: str, type_name: str | None, options: EchoOptions
) -> Iterator[str]:
    """Yield each message's text until Ctrl-C, ``--once``, or the timeout.

    Raises:
        IntrospectionError: unknown topic/type, a bad --field/--filter, or nothing arrived
            within ``--timeout``.
    """
    from rosl.idl.registry import get_message_class
    from rosl.node.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    resolved = resolve_type(session, topic, type_name)
    msg_type = get_message_class(resolved)
    check = compile_filter(options.filter_expr)
    publishers = session.graph().endpoints(PUBLISHER, topic)
    transient = bool(publishers) and all(
        e.qos.get("durability") == "TRANSIENT_LOCAL" for _, e in publishers
    )
    qos = QoSProfile(
        depth=100,
        reliability=ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if transient else DurabilityPolicy.VOLATILE,
    )
    node = session.node()
    inbox: list[tuple[Any, dict[str, Any]]] = []
    subscription = node.create_subscription(
        msg_type, topic, lambda m, info: inbox.append((m, info)), qos
    )
    subscription.log_loss = False  # echo says "A message was lost!!!" itself, as ros2 does
    import rosl

    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    started = time.monotonic()
    shown = 0
    lost_seen = 0
    while rosl.ok():
        if type_name and not shown:  # a publisher that appears while we wait may not match
            check_published_type(node.participant.graph, topic, resolved)
        executor.spin_once(timeout_sec=0.1)
        lost = subscription.lost
        if lost > lost_seen:
            change = lost - lost_seen
            yield (
                f"A message was lost!!!\n\ttotal count change:{change}\n\ttotal count: {lost}\n---"
            )
            lost_seen = lost
        for message, info in inbox:
            value = select_field(message, options.field)
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
