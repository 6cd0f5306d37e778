"""One CLI command's presence on the bus: a complete graph snapshot, and a hidden node if needed.

Graph-only commands (``topic list``, ``node list``...) use a bare participant: it announces
nothing, sends one graph query and returns as soon as every process anyone knows of has
answered (bounded). Commands that subscribe, publish or call get one hidden node,
``_rosl_cli_<pid>`` (hidden like ros2cli's, shown by ``node list -a``).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from rosl.graph.records import CLIENT, PUBLISHER, SERVER, SUBSCRIPTION, is_hidden
from rosl.idl.names import did_you_mean
from rosl.introspection.errors import IntrospectionError

if TYPE_CHECKING:
    from rosl.graph.cache import GraphCache
    from rosl.graph.records import EndpointRecord, NodeRecord
    from rosl.node.node import Node
    from rosl.node.participant import Participant

QUERY_TIMEOUT = 1.0
# a topic the graph does not know after its query is waited for this much longer, before a
# command fails on it: a process of a loaded machine may answer after the query looked
# complete (nobody had answered within its quiet time)
LATE_S = 1.0


class Session:
    """Bus access for one command; use as a context manager."""

    def __init__(self, domain: int | str | None = None) -> None:
        self.domain = domain
        self._participant: Participant | None = None
        self._node: Node | None = None
        self._completed = False

    def __enter__(self) -> Session:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def participant(self) -> Participant:
        """The process's participant (a node's, once :meth:`node` was called)."""
        if self._participant is None:
            if self._node is not None:
                self._participant = self._node.participant
            else:
                from rosl.node.participant import Participant

                self._participant = Participant(self.domain)
        return self._participant

    def graph(self, *, fresh: bool = False) -> GraphCache:
        """The graph after one complete query (bounded by QUERY_TIMEOUT)."""
        if fresh or not self._completed:
            discovery = self.participant.discovery
            first = not fresh and discovery.first_query
            qid = discovery.first_query if first else discovery.query()  # one round trip less
            discovery.wait_complete(qid, timeout=QUERY_TIMEOUT)
            self._completed = True
        return self.participant.graph

    def graph_knowing(self, topic: str) -> GraphCache:
        """The graph, once it knows ``topic`` or :data:`LATE_S` after its query."""
        graph = self.graph()
        if topic not in graph.topics():
            graph.wait_for(lambda: topic in graph.topics(), LATE_S)
        return graph

    def node(self) -> Node:
        """The command's hidden node (created on first use, on this session's domain)."""
        if self._node is None:
            import rosl

            if self._participant is not None:
                self._participant.close()
                self._participant = None
            rosl.init(["rosl"], domain_id=self.domain)
            self._node = rosl.Node(
                f"_rosl_cli_{os.getpid()}", start_parameter_services=False, enable_rosout=False
            )
        return self._node

    def close(self) -> None:
        """Leave the bus."""
        if self._node is not None:
            import rosl

            rosl.shutdown()
            self._node = None
            self._participant = None
        elif self._participant is not None:
            self._participant.close()
            self._participant = None

    # --- lookups with helpful errors ---------------------------------------------------------

    def topic_types(self, topic: str) -> list[str]:
        """The types on ``topic``; error (with close names) when nobody uses it."""
        topics = self.graph().topics()
        if topic not in topics:
            raise IntrospectionError(f"Unknown topic '{topic}'{did_you_mean(topic, set(topics))}")
        return topics[topic]

    def service_types(self, service: str) -> list[str]:
        """The types of ``service``; error (with close names) when nobody serves or calls it."""
        services = self.graph().services()
        if service not in services:
            raise IntrospectionError(
                f"Unknown service '{service}'{did_you_mean(service, set(services))}"
            )
        return services[service]

    def find_node(
        self, fqn: str, *, visible_only: bool = False, missing: str = "Unable to find node '{}'"
    ) -> list[NodeRecord]:
        """Nodes called ``fqn`` (a leading '/' is added); error with close names if none.

        Args:
            fqn: the node's full name.
            visible_only: a hidden node (a name token starting with '_') counts as missing.
            missing: the error's words, ``{}`` standing for the name (ros2's differ by verb).
        """
        name = fqn if fqn.startswith("/") else "/" + fqn
        found = self.graph().find_node(name)
        if not found or (visible_only and not visible(name, False)):
            names = {n.fqn for n in self.graph().nodes() if visible(n.fqn, not visible_only)}
            raise IntrospectionError(missing.format(name) + did_you_mean(name, names))
        return found


def visible(name: str, include_hidden: bool) -> bool:
    """Whether a topic/service/node name is shown (hidden names only on request)."""
    return include_hidden or not is_hidden(name)


def endpoint_kinds(kind: str) -> tuple[str, ...]:
    """The endpoint kinds of 'topic' or 'service' endpoints."""
    return (PUBLISHER, SUBSCRIPTION) if kind == "topic" else (SERVER, CLIENT)


def sorted_endpoints(
    items: list[tuple[NodeRecord, EndpointRecord]],
) -> list[tuple[NodeRecord, EndpointRecord]]:
    """Endpoints ordered by node name then endpoint number (stable output)."""
    return sorted(items, key=lambda pair: (pair[0].fqn, pair[1].endpoint))


def describe_value(value: Any) -> str:
    """Shorten a value for an error message."""
    text = repr(value)
    return text if len(text) < 60 else text[:57] + "..."
