"""The ROS 2 graph on Zenoh: this process's liveliness tokens, and other implementations' nodes.

:class:`LocalEntities` reads this process's own discovery announcements (the ``hello`` that
rosl's discovery sends, whose format is ``rosl.graph.records.to_json``) and keeps one
rmw_zenoh liveliness token per node and endpoint, and one Zenoh subscriber per subscribed
topic. It also gives each endpoint its GID (the hash of its token).

:class:`ForeignGraph` follows ``@ros2_lv/<domain>/**`` (a liveliness query at start, then a
liveliness subscriber) and announces each Zenoh session that has no rosl token — a ROS 2 node
using rmw_zenoh — to the local discovery as if it were a rosl process: ``hello`` records made
from its tokens, answers to graph queries, ``bye`` when its last token goes.
"""

from __future__ import annotations

import itertools
import json
import os
import threading
import time
from typing import TYPE_CHECKING, Any

from rosl.bus import zenoh_wire as wire
from rosl.bus.header import Kind
from rosl.bus.header import topic_hash as hash_topic
from rosl.bus.header import type_hash as hash_type

if TYPE_CHECKING:
    import zenoh

    from rosl.bus.zenoh_transport import ZenohTransport

# the discovery stream of rosl.graph.announce (graph imports bus, not the reverse)
DISCOVERY_TOPIC = "@discovery"
DISCOVERY_TYPE = "rosl/discovery/1"
ROSL_TOKEN = "@rosl_lv"
PERIOD_S = 1.0
_KINDS = {"publisher": wire.PUBLISHER, "subscription": wire.SUBSCRIPTION, "server": wire.SERVER,
          "client": wire.CLIENT}  # fmt: skip
_ROSL_KINDS = {v: k for k, v in _KINDS.items()}


class LocalEntities:
    """This process's nodes and endpoints as liveliness tokens (and subscribers)."""

    def __init__(self, transport: ZenohTransport) -> None:
        self._transport = transport
        self._tokens: dict[str, Any] = {}  # keyexpr -> zenoh.LivelinessToken
        self._subscribed: set[str] = set()
        self._gids: dict[tuple[int, int], bytes] = {}
        self._lock = threading.Lock()
        session = transport.session
        self._rosl_token = session.liveliness().declare_token(
            f"{ROSL_TOKEN}/{transport.domain}/{transport.zid}"
        )

    def gid(self, sender: int, endpoint: int) -> bytes:
        """The GID of one of this process's endpoints (provisional until announced)."""
        gid = self._gids.get((sender, endpoint))
        if gid is None:
            gid = wire.gid_of(f"{self._transport.zid}/{sender:016x}/{endpoint}")
        return gid

    def update(self, process: dict[str, Any] | None) -> None:
        """Declare the tokens of an announced process record; None: undeclare all."""
        entities = [] if process is None else self._entities(process)
        wanted = {entity.keyexpr: entity for entity, _ in entities}
        keys = {
            wire.topic_key(entity.domain, entity.name, entity.type, entity.type_hash)
            for entity, _ in entities
            if entity.kind == wire.SUBSCRIPTION
        }
        with self._lock:
            for keyexpr in [k for k in self._tokens if k not in wanted]:
                self._tokens.pop(keyexpr).undeclare()
            for keyexpr in wanted:
                if keyexpr not in self._tokens and not self._transport_closed():
                    self._tokens[keyexpr] = self._transport.session.liveliness().declare_token(
                        keyexpr
                    )
            gone, self._subscribed = self._subscribed - keys, keys
            for entity, owner in entities:
                if owner is not None:
                    self._gids[owner] = entity.gid
        for key in keys:
            self._transport.subscribe(key)
        for key in gone:
            self._transport.unsubscribe(key)

    def _transport_closed(self) -> bool:
        return bool(getattr(self._transport, "_closed", False))

    def _entities(
        self, process: dict[str, Any]
    ) -> list[tuple[wire.Entity, tuple[int, int] | None]]:
        from rosl.bus.zenoh_transport import type_hash_of

        sender = int(process["sender"], 16)
        domain, zid = self._transport.domain, self._transport.zid
        out: list[tuple[wire.Entity, tuple[int, int] | None]] = []
        for node in process["nodes"]:
            nid = str(node["index"])
            base = dict(domain=domain, zid=zid, nid=nid, enclave="/",
                        namespace=node["namespace"] or "/", node=node["name"])  # fmt: skip
            out.append((wire.Entity(eid=nid, kind=wire.NODE, **base), None))
            for kind, name, type_name, endpoint, qos, *_ in node["endpoints"]:
                service = kind in ("server", "client")
                digest = type_hash_of(type_name, service)
                if not digest or kind not in _KINDS:
                    continue  # a type ROS 2 does not know (rosl's own): no token
                entity = wire.Entity(
                    eid=str(endpoint), kind=_KINDS[kind], name=name, type=type_name,
                    type_hash=digest, qos=wire.Qos.from_words(qos), **base,
                )  # fmt: skip
                out.append((entity, (sender, int(endpoint))))
        return out


class ForeignGraph:
    """Other implementations' nodes, announced to this process's discovery."""

    def __init__(self, transport: ZenohTransport) -> None:
        self._transport = transport
        domain = transport.domain
        self._tokens: dict[str, dict[str, wire.Entity]] = {}  # zid -> keyexpr -> entity
        self._rosl: set[str] = {transport.zid}  # sessions that are rosl processes
        self._lock = threading.Lock()
        self._seq = itertools.count(1)
        self._version = itertools.count(1)
        self._stop = threading.Event()
        session = transport.session
        liveliness = session.liveliness()
        self._rosl_sub = liveliness.declare_subscriber(
            f"{ROSL_TOKEN}/{domain}/*", self._on_rosl_token, history=True
        )
        self._sub = liveliness.declare_subscriber(
            f"{wire.ADMIN_SPACE}/{domain}/**", self._on_token, history=True
        )
        for reply in liveliness.get(f"{wire.ADMIN_SPACE}/{domain}/**", timeout=1.0):
            if reply.ok is not None:
                self._add(str(reply.ok.key_expr))
        self._thread = threading.Thread(target=self._run, name="rosl-zenoh-graph", daemon=True)
        self._thread.start()

    def _on_rosl_token(self, sample: zenoh.Sample) -> None:
        import zenoh

        zid = str(sample.key_expr).rsplit("/", 1)[1]
        with self._lock:
            if sample.kind == zenoh.SampleKind.PUT:
                self._rosl.add(zid)
                known = self._tokens.pop(zid, None)
            else:
                self._rosl.discard(zid)
                known = None
        if known:
            self._bye(zid)  # it was taken for a foreign process before its rosl token came
        if sample.kind == zenoh.SampleKind.PUT and zid != self._transport.zid:
            self._ask_for(zid)

    def _ask_for(self, zid: str) -> None:
        """A rosl process joined: have this process announce itself to it now.

        Its token arrives after its subscriptions did, so this announcement reaches it even
        where the answers to its own first graph query were sent too early to.
        """
        sender = self.sender_of(zid)
        self._send(sender, {"op": "query", "qid": 0, "sender": f"{sender:016x}"})

    def _on_token(self, sample: zenoh.Sample) -> None:
        import zenoh

        key = str(sample.key_expr)
        if sample.kind == zenoh.SampleKind.PUT:
            self._add(key)
            return
        try:
            entity = wire.parse_liveliness(key)
        except ValueError:
            return
        with self._lock:
            tokens = self._tokens.get(entity.zid)
            if tokens is None:
                return
            tokens.pop(key, None)
            empty = not tokens
            if empty:
                del self._tokens[entity.zid]
        if empty:
            self._bye(entity.zid)
        else:
            self._hello(entity.zid, [])

    def _add(self, key: str) -> None:
        try:
            entity = wire.parse_liveliness(key)
        except ValueError:
            return
        with self._lock:
            if entity.zid in self._rosl:
                return
            self._tokens.setdefault(entity.zid, {})[key] = entity
        self._hello(entity.zid, [])

    def zids(self) -> set[str]:
        """The sessions of the foreign processes known now."""
        with self._lock:
            return set(self._tokens)

    def answer(self, query: str) -> None:
        """A graph query of this process went out: every foreign process answers it."""
        with self._lock:
            zids = list(self._tokens)
        for zid in zids:
            self._hello(zid, [query])

    def _run(self) -> None:
        while not self._stop.wait(PERIOD_S):
            with self._lock:
                zids = list(self._tokens)
            for zid in zids:
                self._hello(zid, [])

    def close(self) -> None:
        """Stop announcing."""
        self._stop.set()

    @staticmethod
    def sender_of(zid: str) -> int:
        """The rosl process id a foreign session is announced under."""
        return int(zid[-16:].rjust(16, "0"), 16) | 1

    def _hello(self, zid: str, reply_to: list[str]) -> None:
        with self._lock:
            entities = list(self._tokens.get(zid, {}).values())
        if not entities:
            return
        sender = self.sender_of(zid)
        process = {
            "sender": f"{sender:016x}", "pid": 0, "host": f"zenoh:{zid}",
            "version": next(self._version), "lockstep": False, "nodes": _nodes(entities),
        }  # fmt: skip
        self._send(sender, {"op": "hello", "process": process, "known": [], "reply_to": reply_to})

    def _bye(self, zid: str) -> None:
        sender = self.sender_of(zid)
        self._send(sender, {"op": "bye", "sender": f"{sender:016x}"})

    def _send(self, sender: int, message: dict[str, Any]) -> None:
        from rosl.bus.header import HEADER, MAGIC, VERSION

        body = json.dumps(message, separators=(",", ":")).encode()
        head = HEADER.pack(
            MAGIC, VERSION, Kind.DISCOVERY, 0, 1, sender, next(self._seq),
            hash_topic(DISCOVERY_TOPIC), hash_type(DISCOVERY_TYPE), 0, 0, len(body),
            time.time_ns(),
        )  # fmt: skip
        self._transport.inject(0, head + body)


def _nodes(entities: list[wire.Entity]) -> list[dict[str, Any]]:
    nodes: dict[str, dict[str, Any]] = {}
    for entity in sorted(entities, key=lambda e: (e.nid, e.kind != wire.NODE, e.eid)):
        node = nodes.setdefault(entity.nid, {
            "name": entity.node, "namespace": entity.namespace or "/",
            "index": _number(entity.nid), "endpoints": [],
        })  # fmt: skip
        if entity.kind == wire.NODE:
            node["name"], node["namespace"] = entity.node, entity.namespace or "/"
            continue
        node["endpoints"].append([
            _ROSL_KINDS[entity.kind], entity.name, entity.type, _number(entity.eid),
            entity.qos.words(), {}, "",
        ])  # fmt: skip
    return list(nodes.values())


def _number(text: str) -> int:
    try:
        return int(text) & 0xFFFF
    except ValueError:
        return int.from_bytes(os.urandom(2), "little")
