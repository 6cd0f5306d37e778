"""``topic list/info/type/find``: the graph's topics in ros2cli's text formats."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rosl.graph.records import LOST_FROM, PUBLISHER, SUBSCRIPTION, gid
from rosl.introspection.session import sorted_endpoints, visible

if TYPE_CHECKING:
    from rosl.graph.records import EndpointRecord, NodeRecord
    from rosl.introspection.session import Session


def list_topics(
    session: Session,
    *,
    show_types: bool = False,
    count: bool = False,
    verbose: bool = False,
    include_hidden: bool = False,
) -> list[str]:
    """The lines ``ros2 topic list`` prints."""
    graph = session.graph()
    topics = {n: t for n, t in graph.topics().items() if visible(n, include_hidden)}
    if count:
        return [str(len(topics))]
    if not verbose:
        return [f"{n} [{', '.join(t)}]" if show_types else n for n, t in topics.items()]
    lines = ["Published topics:"]
    lines += _verbose_section(session, topics, PUBLISHER, "publisher")
    lines += ["", "Subscribed topics:"]
    lines += _verbose_section(session, topics, SUBSCRIPTION, "subscriber")
    return [*lines, ""]


def _verbose_section(
    session: Session, topics: dict[str, list[str]], kind: str, word: str
) -> list[str]:
    lines = []
    for name, types in topics.items():
        n = session.graph().count(kind, name)
        if n:
            lines.append(f" * {name} [{', '.join(types)}] {n} {word}{'s' if n > 1 else ''}")
    return lines


def find_topics(session: Session, type_name: str, *, include_hidden: bool = False) -> list[str]:
    """Topics carrying ``type_name`` (``pkg/msg/T`` or ``pkg/T``; other text matches none)."""
    from rosl.idl.errors import InterfaceError
    from rosl.idl.names import canonical

    try:
        wanted = canonical(type_name)
    except InterfaceError:
        return []  # as ros2: a name that is no type finds nothing
    return [
        name
        for name, types in session.graph().topics().items()
        if wanted in types and visible(name, include_hidden)
    ]


def topic_info(
    session: Session, topic: str, *, verbose: bool = False, stats: bool = False
) -> list[str]:
    """The lines ``ros2 topic info [-v]`` prints; ``stats`` adds each endpoint's counters."""
    types = session.topic_types(topic)
    graph = session.graph()
    end = "\n" if verbose else ""
    type_text = types[0] if len(types) == 1 else str(types)
    lines = [f"Type: {type_text}{end}"]
    pubs = sorted_endpoints(graph.endpoints(PUBLISHER, topic))
    subs = sorted_endpoints(graph.endpoints(SUBSCRIPTION, topic))
    lines.append(f"Publisher count: {len(pubs)}{end}")
    if verbose:
        lines += [_endpoint_block(node, e, stats, subs) + "\n" for node, e in pubs]
    lines.append(f"Subscription count: {len(subs)}{end}")
    if verbose:
        lines += [_endpoint_block(node, e, stats, pubs) + "\n" for node, e in subs]
    return lines


def _duration(ns: object) -> str:
    return f"{ns} nanoseconds" if isinstance(ns, int) and ns > 0 else "Infinite"


def _incompatible(
    endpoint: EndpointRecord, others: list[tuple[NodeRecord, EndpointRecord]]
) -> list[str]:
    """A line per endpoint on the other side that this one exchanges nothing with (QoS)."""
    from rosl.node.qos_compatibility import mismatches

    lines = []
    for node, other in others:
        if other.type != endpoint.type:
            continue  # another type matches nothing anyway
        if endpoint.kind == PUBLISHER:
            found, word = mismatches(endpoint.qos, other.qos), "to"
        else:
            found, word = mismatches(other.qos, endpoint.qos), "from"
        if found:
            reasons = "; ".join(f"{m.kind.name}: {m.reason}" for m in found)
            lines.append(f"Incompatible QoS: no messages {word} {node.fqn} ({reasons})")
    return lines


def _endpoint_block(
    node: NodeRecord,
    endpoint: EndpointRecord,
    stats: bool,
    others: list[tuple[NodeRecord, EndpointRecord]],
) -> str:
    qos = endpoint.qos
    history = qos.get("history", "KEEP_LAST")
    depth = f"{history} ({qos.get('depth', 0)})" if history == "KEEP_LAST" else history
    lines = [
        f"Node name: {node.name}",
        f"Node namespace: {node.namespace}",
        f"Topic type: {endpoint.type}",
        f"Endpoint type: {endpoint.kind.upper()}",
        f"GID: {gid(node.process, endpoint.endpoint)}",
        "QoS profile:",
        f"  Reliability: {qos.get('reliability', 'UNKNOWN')}",
        f"  History (Depth): {depth}",
        f"  Durability: {qos.get('durability', 'UNKNOWN')}",
        f"  Lifespan: {_duration(qos.get('lifespan'))}",
        f"  Deadline: {_duration(qos.get('deadline'))}",
        f"  Liveliness: {qos.get('liveliness', 'AUTOMATIC')}",
        f"  Liveliness lease duration: {_duration(qos.get('liveliness_lease_duration'))}",
        *_incompatible(endpoint, others),
    ]
    if not stats:
        return "\n".join(lines)
    counts = endpoint.stats
    if endpoint.kind == PUBLISHER:
        key = LOST_FROM + gid(node.process, endpoint.endpoint)
        lost = sum(other.stats.get(key, 0) for _, other in others)
        lines.append(f"Messages sent: {counts.get('sent', 0)} (lost on the way: {lost})")
    else:
        lines.append(
            f"Messages received: {counts.get('received', 0)} (lost: {counts.get('lost', 0)}, "
            f"dropped: {counts.get('dropped', 0)}, wrong type: {counts.get('mismatched', 0)})"
        )
        lines += _lost_from(counts, others)
    return "\n".join(lines)


def _lost_from(
    counts: dict[str, int], publishers: list[tuple[NodeRecord, EndpointRecord]]
) -> list[str]:
    """A line per publisher this subscription lost messages from (sequence gaps)."""
    names = {gid(node.process, e.endpoint): node.fqn for node, e in publishers}
    found = [
        (key.removeprefix(LOST_FROM), n) for key, n in counts.items() if key.startswith(LOST_FROM)
    ]
    return [f"  Lost from {names.get(source, source)}: {count}" for source, count in found]
