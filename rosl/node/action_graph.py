"""rclpy.action's graph queries, answered from the node's view of the graph."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rosl.graph import actions

if TYPE_CHECKING:
    from rosl.node.node import Node


def get_action_names_and_types(node: Node) -> list[tuple[str, list[str]]]:
    """Every action in the graph with its types."""
    return list(actions.names_and_types(node.participant.graph).items())


def _by_node(node: Node, name: str, namespace: str, servers: bool) -> list[tuple[str, list[str]]]:
    fqn = (namespace.rstrip("/") or "") + "/" + name.lstrip("/")
    found: dict[str, set[str]] = {}
    for record in node.participant.graph.find_node(fqn):
        entries = actions.servers(record) if servers else actions.clients(record)
        for action, types in entries.items():
            found.setdefault(action, set()).update(types)
    return [(action, sorted(types)) for action, types in sorted(found.items())]


def get_action_server_names_and_types_by_node(
    node: Node, remote_node_name: str, remote_node_namespace: str
) -> list[tuple[str, list[str]]]:
    """The actions a node serves, with their types."""
    return _by_node(node, remote_node_name, remote_node_namespace, servers=True)


def get_action_client_names_and_types_by_node(
    node: Node, remote_node_name: str, remote_node_namespace: str
) -> list[tuple[str, list[str]]]:
    """The actions a node is a client of, with their types."""
    return _by_node(node, remote_node_name, remote_node_namespace, servers=False)
