"""What discovery knows: processes, their nodes, and the nodes' endpoints (plain records)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

PUBLISHER = "publisher"
SUBSCRIPTION = "subscription"
SERVER = "server"
CLIENT = "client"
ENDPOINT_KINDS = (PUBLISHER, SUBSCRIPTION, SERVER, CLIENT)


@dataclass(frozen=True, slots=True)
class EndpointRecord:
    """One publisher, subscription, service server or client.

    Attributes:
        kind: one of ENDPOINT_KINDS.
        name: the fully qualified topic or service name.
        type: the canonical type name.
        endpoint: the endpoint's number within its process.
        qos: QoS words (reliability, durability, history, depth, ...).
        stats: counters: ``sent`` for writers; ``received``, ``lost`` and ``dropped`` for
            readers, and ``lost from <gid>`` per publisher with loss.
        digest: a fingerprint of the type's definition as the endpoint's process reads it
            (empty when unknown): two endpoints of one type name may still disagree on fields.
    """

    kind: str
    name: str
    type: str
    endpoint: int
    qos: dict[str, Any] = field(default_factory=dict, hash=False, compare=False)
    stats: dict[str, int] = field(default_factory=dict, hash=False, compare=False)
    digest: str = field(default="", hash=False, compare=False)


@dataclass(frozen=True, slots=True)
class NodeRecord:
    """A node and its endpoints."""

    name: str
    namespace: str
    process: int  # the sender id of its process
    index: int  # its number within the process
    endpoints: tuple[EndpointRecord, ...] = ()

    @property
    def fqn(self) -> str:
        """The fully qualified name, e.g. ``/ns/talker``."""
        return (self.namespace.rstrip("/") or "") + "/" + self.name

    @property
    def key(self) -> tuple[int, int]:
        """Unique in the graph: (process, index)."""
        return (self.process, self.index)


@dataclass(frozen=True, slots=True)
class ProcessRecord:
    """A process that announced nodes."""

    sender: int
    pid: int
    host: str
    nodes: tuple[NodeRecord, ...]
    version: int
    seen: float = 0.0  # time.monotonic() of the last announcement
    lockstep: bool = False  # spins an executor that answers a lock-stepped simulator
    shm: str = ""  # where it maps shared memory (``bus.shm.host_identity``); "": it does not


LOST_FROM = "lost from "  # a reader's stats key prefix: messages lost from the publisher (gid)


def gid(process: int, endpoint: int) -> str:
    """ROS 2's dotted GID text for an endpoint (16 bytes: process id, endpoint, zeros)."""
    raw = process.to_bytes(8, "little") + endpoint.to_bytes(2, "little") + bytes(6)
    return ".".join(f"{b:02x}" for b in raw)


def is_hidden(name: str) -> bool:
    """ROS 2's rule: a name with any token starting with ``_`` is hidden."""
    return any(token.startswith("_") for token in name.split("/") if token)


def to_json(record: ProcessRecord) -> dict[str, Any]:
    """Encode a process record as plain data (for the discovery wire format)."""
    return {
        "sender": f"{record.sender:016x}",
        "pid": record.pid,
        "host": record.host,
        "version": record.version,
        "lockstep": record.lockstep,
        "shm": record.shm,
        "nodes": [
            {
                "name": n.name,
                "namespace": n.namespace,
                "index": n.index,
                "endpoints": [
                    [e.kind, e.name, e.type, e.endpoint, e.qos, e.stats, e.digest]
                    for e in n.endpoints
                ],
            }
            for n in record.nodes
        ],
    }


def from_json(data: dict[str, Any], seen: float) -> ProcessRecord:
    """Decode a process record; raises KeyError/TypeError/ValueError on malformed input."""
    sender = int(data["sender"], 16)
    nodes = tuple(
        NodeRecord(
            name=str(n["name"]),
            namespace=str(n["namespace"]),
            process=sender,
            index=int(n["index"]),
            endpoints=tuple(
                EndpointRecord(
                    str(k), str(name), str(t), int(e), dict(q), dict(s), str(d[0]) if d else ""
                )
                for k, name, t, e, q, s, *d in n["endpoints"]
            ),
        )
        for n in data["nodes"]
    )
    return ProcessRecord(
        sender, int(data["pid"]), str(data["host"]), nodes, int(data["version"]), seen,
        bool(data.get("lockstep", False)), str(data.get("shm", "")),
    )  # fmt: skip
