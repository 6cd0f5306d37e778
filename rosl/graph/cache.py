"""The graph as this process has heard it, with liveliness, and waits on its changes."""

from __future__ import annotations

import threading
import time
from collections import defaultdict
from dataclasses import replace
from typing import TYPE_CHECKING

from rosl.graph.records import (
    CLIENT,
    PUBLISHER,
    SERVER,
    SUBSCRIPTION,
    EndpointRecord,
    NodeRecord,
    ProcessRecord,
)

if TYPE_CHECKING:
    from collections.abc import Callable

LEASE_S = 3.5  # a process not heard from for this long is gone
MAX_PROCESSES = 4096  # processes followed at once: a flood of made-up ones is refused


class GraphCache:
    """Processes → nodes → endpoints, thread safe; every change wakes waiters."""

    def __init__(self, lease_s: float = LEASE_S) -> None:
        self.lease_s = lease_s
        self._processes: dict[int, ProcessRecord] = {}
        self._changed = threading.Condition()
        self.generation = 0  # increments on every change
        self.refused = 0  # announcements of new processes refused while the table was full
        # called (with no lock held) after each change; one that returns False is dropped
        self.listeners: list[Callable[[], bool]] = []

    # --- updates -----------------------------------------------------------------------------

    def update(self, record: ProcessRecord) -> bool:
        """Store a process's announcement; return whether the graph changed."""
        with self._changed:
            old = self._processes.get(record.sender)
            if old is None and len(self._processes) >= MAX_PROCESSES:
                self.refused += 1  # known processes keep their place; leases free room
                return False
            self._processes[record.sender] = record
            changed = old is None or old.nodes != record.nodes
            if changed:
                self._bump()
        if changed:
            self._tell()
        return changed

    def renew(self, sender: int, version: int, seen: float) -> bool:
        """Renew a process's lease when ``version`` is the record held; whether it was."""
        with self._changed:
            old = self._processes.get(sender)
            if old is None or old.version != version:
                return False
            self._processes[sender] = replace(old, seen=seen)
            return True

    def remove(self, sender: int) -> None:
        """Forget a process (it said goodbye)."""
        with self._changed:
            gone = self._processes.pop(sender, None) is not None
            if gone:
                self._bump()
        if gone:
            self._tell()

    def expire(self, now: float | None = None) -> list[ProcessRecord]:
        """Forget processes whose lease ran out; return them."""
        moment = time.monotonic() if now is None else now
        with self._changed:
            gone = [p for p in self._processes.values() if moment - p.seen > self.lease_s]
            for process in gone:
                del self._processes[process.sender]
            if gone:
                self._bump()
        if gone:
            self._tell()
        return gone

    def _bump(self) -> None:
        self.generation += 1
        self._changed.notify_all()

    def _tell(self) -> None:
        for listener in list(self.listeners):
            if not listener():
                self.listeners.remove(listener)

    def wait_for(self, predicate: Callable[[], bool], timeout: float | None) -> bool:
        """Block until ``predicate()`` holds (re-checked on every change) or the timeout."""
        with self._changed:
            return self._changed.wait_for(predicate, timeout)

    def wait_change(self, generation: int, timeout: float) -> int:
        """Block until the graph differs from ``generation`` (or timeout); return the new one."""
        with self._changed:
            self._changed.wait_for(lambda: self.generation != generation, timeout)
            return self.generation

    # --- queries -----------------------------------------------------------------------------

    def processes(self) -> list[ProcessRecord]:
        """Every known process."""
        with self._changed:
            return list(self._processes.values())

    def senders(self) -> set[int]:
        """The ids of every known process."""
        with self._changed:
            return set(self._processes)

    def nodes(self) -> list[NodeRecord]:
        """Every known node, sorted by fully qualified name."""
        with self._changed:
            found = [n for p in self._processes.values() for n in p.nodes]
        return sorted(found, key=lambda n: (n.fqn, n.key))

    def endpoints(
        self, kind: str | None = None, name: str | None = None
    ) -> list[tuple[NodeRecord, EndpointRecord]]:
        """Endpoints of a kind and/or on a name, with the node that owns each."""
        return [
            (node, e)
            for node in self.nodes()
            for e in node.endpoints
            if (kind is None or e.kind == kind) and (name is None or e.name == name)
        ]

    def sender(
        self, process: int, endpoint: int, kind: str | None = None, name: str | None = None
    ) -> tuple[NodeRecord, EndpointRecord] | None:
        """The endpoint a message came from (its process and endpoint number), with its node."""
        with self._changed:
            record = self._processes.get(process)
        for node in record.nodes if record is not None else ():
            for e in node.endpoints:
                same_kind = kind is None or e.kind == kind
                if e.endpoint == endpoint and same_kind and (name is None or e.name == name):
                    return node, e
        return None

    def topics(self) -> dict[str, list[str]]:
        """Topic name → sorted types, over publishers and subscriptions."""
        return self._names((PUBLISHER, SUBSCRIPTION))

    def services(self) -> dict[str, list[str]]:
        """Service name → sorted types, over servers and clients."""
        return self._names((SERVER, CLIENT))

    def _names(self, kinds: tuple[str, ...]) -> dict[str, list[str]]:
        found: dict[str, set[str]] = defaultdict(set)
        for _, endpoint in self.endpoints():
            if endpoint.kind in kinds:
                found[endpoint.name].add(endpoint.type)
        return {name: sorted(types) for name, types in sorted(found.items())}

    def all_on_host(self, kind: str, name: str, host: str) -> bool:
        """Whether every process with an endpoint of a kind on a name maps rings on ``host``.

        See ``bus/shm.py``; True when there is no such endpoint.
        """
        with self._changed:
            processes = list(self._processes.values())
        return all(
            p.shm == host
            for p in processes
            if any(e.kind == kind and e.name == name for n in p.nodes for e in n.endpoints)
        )

    def count(self, kind: str, name: str) -> int:
        """How many endpoints of a kind are on a name (e.g. subscriptions of /chatter)."""
        return len(self.endpoints(kind, name))

    def find_node(self, fqn: str) -> list[NodeRecord]:
        """Nodes with this fully qualified name (more than one means a name clash)."""
        return [n for n in self.nodes() if n.fqn == fqn]

    def has_server(self, name: str) -> bool:
        """Whether some node serves the service ``name``."""
        return bool(self.endpoints(SERVER, name))

    def clients(self, name: str) -> int:
        """How many clients the service ``name`` has."""
        return self.count(CLIENT, name)
