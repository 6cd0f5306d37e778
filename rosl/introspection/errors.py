"""Errors of the introspection commands (unknown topic/node/service, nothing answering)."""

from __future__ import annotations

from rosl.graph.errors import GraphError


class IntrospectionError(GraphError):
    """A topic, service, node or parameter the user named is not there, or did not answer."""
