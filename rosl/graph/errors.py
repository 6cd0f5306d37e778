"""Errors about the graph: unknown nodes, topics or services."""

from __future__ import annotations

from rosl.errors import RoslError


class GraphError(RoslError):
    """A node, topic or service that is not in the graph, or a query that cannot complete."""
