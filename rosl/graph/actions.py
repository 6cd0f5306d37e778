"""Actions in the graph, found as ROS 2 finds them: by their feedback topics.

An action server publishes ``<action>/_action/feedback`` (type ``<Action>_FeedbackMessage``)
and an action client subscribes to it (rcl_action's graph queries work the same way), so
actions need no announcement of their own.
"""

from __future__ import annotations

from collections import defaultdict
from typing import TYPE_CHECKING

from rosl.graph.records import PUBLISHER, SUBSCRIPTION

if TYPE_CHECKING:
    from collections.abc import Iterable

    from rosl.graph.cache import GraphCache
    from rosl.graph.records import EndpointRecord, NodeRecord

FEEDBACK_SUFFIX = "/_action/feedback"
TYPE_SUFFIX = "_FeedbackMessage"


def _actions(endpoints: Iterable[EndpointRecord], kinds: tuple[str, ...]) -> dict[str, list[str]]:
    found: dict[str, set[str]] = defaultdict(set)
    for endpoint in endpoints:
        if endpoint.kind in kinds and endpoint.name.endswith(FEEDBACK_SUFFIX):
            found[endpoint.name[: -len(FEEDBACK_SUFFIX)]].add(
                endpoint.type.removesuffix(TYPE_SUFFIX)
            )
    return {name: sorted(types) for name, types in sorted(found.items())}


def names_and_types(graph: GraphCache) -> dict[str, list[str]]:
    """Every action in the graph (served or used) → its sorted types."""
    return _actions((e for _, e in graph.endpoints()), (PUBLISHER, SUBSCRIPTION))


def servers(node: NodeRecord) -> dict[str, list[str]]:
    """The actions ``node`` serves → their types."""
    return _actions(node.endpoints, (PUBLISHER,))


def clients(node: NodeRecord) -> dict[str, list[str]]:
    """The actions ``node`` is a client of → their types."""
    return _actions(node.endpoints, (SUBSCRIPTION,))
