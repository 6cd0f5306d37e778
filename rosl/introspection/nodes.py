"""``node list`` and ``node info`` in ros2cli's formats."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rosl.graph import actions
from rosl.graph.records import CLIENT, PUBLISHER, SERVER, SUBSCRIPTION
from rosl.introspection.errors import IntrospectionError
from rosl.introspection.session import visible

if TYPE_CHECKING:
    from rosl.introspection.session import Session

DUPLICATE_WARNING = (
    "WARNING: Be aware that there are nodes in the graph that share an exact name, which can "
    "have unintended side effects."
)


def list_nodes(
    session: Session, *, include_hidden: bool = False, count: bool = False
) -> tuple[list[str], list[str]]:
    """(stdout lines, stderr lines) of ``ros2 node list``."""
    names = [n.fqn for n in session.graph().nodes() if visible(n.fqn, include_hidden)]
    if count:
        return [str(len(names))], []
    warnings = [DUPLICATE_WARNING] if len(set(names)) != len(names) else []
    return sorted(names), warnings


def node_info(
    session: Session, name: str, *, include_hidden: bool = False
) -> tuple[list[str], list[str]]:
    """(stdout lines, stderr lines) of ``ros2 node info NODE``: the six sections.

    Actions are found by their feedback topics (hidden names, so not in the topic sections).

    As ros2: a hidden node is only found with ``include_hidden``.

    Raises:
        IntrospectionError: ros2's "Unable to find node '/x'" (with the closest visible name).
    """
    fqn = name if name.startswith("/") else "/" + name
    if not visible(fqn, include_hidden) and session.graph().find_node(fqn):
        raise IntrospectionError(f"Unable to find node '{fqn}'")  # hidden: ros2's words only
    found = session.find_node(fqn, visible_only=not include_hidden)
    node = found[0]
    warnings = []
    if len(found) > 1:
        warnings.append(
            f'There are {len(found)} nodes in the graph with the exact name "{node.fqn}". '
            "You are seeing information about only one of them."
        )
    lines = [node.fqn]
    for title, kind in (
        ("Subscribers", SUBSCRIPTION),
        ("Publishers", PUBLISHER),
        ("Service Servers", SERVER),
        ("Service Clients", CLIENT),
    ):
        lines.append(f"  {title}:")
        entries: dict[str, set[str]] = {}
        for endpoint in node.endpoints:
            if endpoint.kind == kind and visible(endpoint.name, include_hidden):
                entries.setdefault(endpoint.name, set()).add(endpoint.type)
        lines += [f"    {n}: {', '.join(sorted(t))}" for n, t in sorted(entries.items())]
    for title, named in (
        ("Action Servers", actions.servers(node)),
        ("Action Clients", actions.clients(node)),
    ):
        lines.append(f"  {title}:")
        lines += [
            f"    {n}: {', '.join(t)}" for n, t in named.items() if visible(n, include_hidden)
        ]
    return _blank_empty_sections(lines), warnings


def _blank_empty_sections(lines: list[str]) -> list[str]:
    # ros2 prints an empty line for a section with no entries
    out: list[str] = []
    for index, line in enumerate(lines):
        out.append(line)
        is_title = line.startswith("  ") and line.endswith(":") and not line.startswith("    ")
        following = lines[index + 1] if index + 1 < len(lines) else ""
        if is_title and not following.startswith("    "):
            out.append("")
    if out and out[-1] == "" and len(out) > 1 and out[-2] == "":
        out.pop()
    return out
