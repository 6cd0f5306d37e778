"""The Zenoh transport (``ROSL_TRANSPORT=zenoh``): rosl's seam over Zenoh in rmw_zenoh's format.

Datagrams from the layers above are read here and mapped onto Zenoh as a ROS 2 node using
``rmw_zenoh_cpp`` would put them (see :mod:`rosl.bus.zenoh_wire`):

* a message (``DATA``) is a ``put`` of its CDR bytes on the topic's key, with the attachment;
* a request is a ``get`` on the service's key (target ALL_COMPLETE); a server's queryable turns
  the query into a ``REQUEST`` delivery and its response into the query's ``reply``;
* this process's nodes and endpoints, read from its own discovery announcements, become
  liveliness tokens; a subscription becomes a Zenoh subscriber on its topic's key;
* everything else rosl says (its discovery, transient-local replays, lock-step) travels as
  rosl datagrams under ``@rosl/<domain>/<channel>``, so rosl processes keep their full graph;
* nodes of other implementations (liveliness tokens of sessions without a rosl token) are
  announced to the local graph by :class:`rosl.bus.zenoh_graph.ForeignGraph`.

Received messages become :class:`~rosl.bus.wire.Delivery` records at once (Zenoh reassembles
and orders; see :mod:`rosl.bus.zenoh_receive`); the receivers' readers keep filtering by topic
and counting per publisher. A publisher's plain message skips rosl's header altogether: its
writer calls the put that :meth:`ZenohTransport.direct_sender` made for it.
"""

from __future__ import annotations

import contextlib
import json
import threading
import time
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosl.bus import zenoh_wire as wire
from rosl.bus.coalesce import split_records
from rosl.bus.errors import BusError
from rosl.bus.header import ADDRESS, ADDRESS_SIZE, HEADER, HEADER_SIZE, Flags, Kind
from rosl.bus.header import topic_hash as hash_topic
from rosl.bus.header import type_hash as hash_type
from rosl.bus.pacing import pacer_from_env
from rosl.bus.transport import channel_of
from rosl.bus.wire import Delivery
from rosl.bus.zenoh_receive import ZenohReceiver, read_attachment, sample_callback

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    import zenoh

    from rosl.bus.auth import Auth
    from rosl.bus.transport import Buffer

MAX_DATAGRAM = 1 << 30  # Zenoh fragments and reassembles: rosl never splits a message
ROSL_PREFIX = "@rosl"
SETTLE_S = 2.0  # the longest a new session waits for links to the sessions in the graph


@dataclass(slots=True)
class _Route:
    """What rosl's hashes stand for on Zenoh: one topic or service of this process."""

    name: str
    type: str
    key: str  # the data or service key expression ("" when the type has no hash here)
    service: bool


ROSL_ONLY = "rosl_msgs/"  # rosl's own control types (lock-step answers): rosl datagrams only


def type_hash_of(type_name: str, service: bool) -> str:
    """The RIHS01 hash of a type this process can load ("" when it cannot, or rosl's own)."""
    from rosl.idl import registry
    from rosl.idl.errors import InterfaceError

    if type_name.startswith(ROSL_ONLY):
        return ""  # no ROS 2 node reads them; they keep rosl's process and endpoint ids
    try:
        if service:
            registry.get_service_class(type_name)
            registry.get_message_class(f"{type_name}_Event")
            return registry.store().service_type_hash(type_name)
        registry.get_message_class(type_name)
        return registry.store().ros2_type_hash(type_name)
    except (InterfaceError, KeyError, ValueError):
        return ""


class ZenohTransport:
    """One Zenoh session for one domain, behind rosl's transport seam."""

    def __init__(self, domain: int) -> None:
        from rosl.bus.zenoh_config import open_session, session_config
        from rosl.bus.zenoh_graph import ForeignGraph, LocalEntities
        from rosl.bus.zenoh_identity import Identities

        self.name = "the Zenoh transport"
        self.fix_hint = (
            "check ZENOH_SESSION_CONFIG_URI / ZENOH_CONFIG_OVERRIDE (a router: rosl zenoh router)"
        )
        self.domain = domain
        self.max_datagram = MAX_DATAGRAM
        self.pacer = pacer_from_env(True)
        self.auth: Auth | None = (
            None  # Zenoh authenticates links itself (TLS, user/password in its config)
        )
        self._closed = False
        self.session: zenoh.Session = open_session(session_config())
        self.zid = str(self.session.info.zid())
        self._lock = threading.RLock()
        self.receivers: tuple[ZenohReceiver, ...] = ()  # replaced whole: read without a lock
        self._routes: dict[int, _Route] = {}  # topic/service hash -> route
        self._publishers: dict[str, Any] = {}  # key -> zenoh.Publisher
        self._queryables: dict[str, Any] = {}
        self._subscribers: dict[str, Any] = {}  # key -> zenoh.Subscriber
        self._wildcard: Any = None  # the subscriber on every topic (recorders)
        self._queries: dict[tuple[int, int, int], tuple[Any, bytes]] = {}
        self._key_hashes: dict[str, tuple[int, int]] = {}
        self._cached: dict[int, int] = {}  # topic -> its transient-local publishers (cached)
        self.local = LocalEntities(self)
        self.identities = Identities(self.session, domain, self.zid)
        self._rosl_sub = self.session.declare_subscriber(
            f"{ROSL_PREFIX}/{domain}/**", self._on_rosl_datagram
        )
        self.foreign = ForeignGraph(self)
        _close_before_threads_join(self)
        self._settle()

    def _settle(self, bound_s: float = SETTLE_S) -> None:
        """Wait (bounded) for direct links to the sessions already in the graph.

        Zenoh peers exchange their subscriptions when they link up; until then, what another
        rosl process says to this one (the answers to its first graph query) may be dropped.
        """
        from rosl.bus.zenoh_graph import ROSL_TOKEN

        known = {self.zid}
        for reply in self.session.liveliness().get(f"{ROSL_TOKEN}/{self.domain}/*", timeout=1.0):
            if reply.ok is not None:
                known.add(str(reply.ok.key_expr).rsplit("/", 1)[1])
        known |= self.foreign.zids()
        known.discard(self.zid)
        deadline = time.monotonic() + bound_s
        while known and time.monotonic() < deadline:
            linked = {str(zid) for zid in self.session.info.peers_zid()}
            if known <= linked:
                time.sleep(0.05)  # their declarations follow the link at once
                return
            time.sleep(0.01)

    # --- routes -------------------------------------------------------------------------------

    def route(self, topic: int, name: str, type_name: str, service: bool) -> _Route:
        """Learn (once) the key expression of a topic or service hash."""
        with self._lock:
            known = self._routes.get(topic)
            if known is not None and known.key:
                return known
            digest = type_hash_of(type_name, service)
            key = wire.topic_key(self.domain, name, type_name, digest) if digest else ""
            known = _Route(name, type_name, key, service)
            self._routes[topic] = known
            return known

    def register_writer(self, topic: int, name: str, type_name: str, kind: int) -> None:
        """A writer was made (the seam's optional hook): know its key; servers get queryables."""
        if kind == Kind.DISCOVERY:
            return
        service = kind in (Kind.REQUEST, Kind.RESPONSE, Kind.FAILURE)
        route = self.route(topic, name, type_name, service)
        if kind == Kind.RESPONSE and route.key:
            with self._lock:
                if route.key not in self._queryables:
                    self._queryables[route.key] = self.session.declare_queryable(
                        route.key, self._on_query, complete=True
                    )

    def keep_history(self, topic: int, depth: int, reliable: bool) -> None:
        """A transient-local publisher was made (the seam's optional hook): cache on Zenoh.

        Its topic's key is put through an ``AdvancedPublisher`` keeping ``depth`` samples, as
        rmw_zenoh declares one (see :mod:`rosl.bus.zenoh_history`); late subscriptions of
        any process, ROS 2's too, are served from it, so rosl's own replays of the topic are
        not sent.
        """
        from rosl.bus.zenoh_history import declare_cached_publisher

        with self._lock:
            route = self._routes.get(topic)
            if route is None or not route.key or self._closed:
                return
            self._cached[topic] = self._cached.get(topic, 0) + 1
            if self._cached[topic] > 1:
                return  # one cache per topic and process (the first publisher's depth)
            old = self._publishers.pop(route.key, None)
            self._publishers[route.key] = declare_cached_publisher(
                self.session, route.key, depth, reliable
            )
        if old is not None:
            old.undeclare()

    def drop_history(self, topic: int) -> None:
        """A transient-local publisher went: its topic's cache goes with the last of them."""
        with self._lock:
            count = self._cached.pop(topic, 0)
            if count > 1:
                self._cached[topic] = count - 1
                return
            route = self._routes.get(topic)
            cached = self._publishers.pop(route.key, None) if route and count else None
        if cached is not None and not self._closed:
            cached.undeclare()

    def subscribe(self, key: str) -> None:
        """Declare Zenoh subscribers on a data key and its Humble form (idempotent).

        ROS 2 Humble's rmw_zenoh has no type hashes: it writes ``TypeHashNotSupported`` in
        their place, so its publishers are heard on that key too (matched by name and type).
        """
        with self._lock:
            for each in (key, wire.humble_key(key)):
                if each not in self._subscribers and not self._closed:
                    self._subscribers[each] = self.session.declare_subscriber(
                        each, sample_callback(self, self.key_hashes(each), False)
                    )

    def unsubscribe(self, key: str) -> None:
        """Undeclare a data key's subscribers."""
        with self._lock:
            subscribers = [self._subscribers.pop(k, None) for k in (key, wire.humble_key(key))]
        for subscriber in subscribers:
            if subscriber is not None:
                subscriber.undeclare()

    def subscribe_all(self) -> None:
        """Receive every topic of the domain (recorders and monitors)."""
        with self._lock:
            if self._wildcard is None and not self._closed:
                self._wildcard = self.session.declare_subscriber(
                    f"{self.domain}/**", sample_callback(self, None, True)
                )

    # --- sending --------------------------------------------------------------------------------

    def send(self, channel: int, parts: Sequence[Buffer]) -> None:
        """Map one rosl datagram onto Zenoh (see the module docstring)."""
        data = b"".join(parts)
        if len(data) < HEADER_SIZE or self._closed:
            return
        (_, _, kind, flags, _, sender, seq, topic, _, _, endpoint, _, stamp) = HEADER.unpack_from(
            data
        )
        payload = memoryview(data)[HEADER_SIZE:]
        if kind == Kind.DISCOVERY:
            self._on_own_discovery(bytes(payload))
        route = self._routes.get(topic)
        routed = route is not None and route.key and not flags & Flags.LOCKSTEP
        if routed and kind == Kind.DATA and route is not None:
            gid = self.local.gid(sender, endpoint)
            if flags & Flags.BATCH:
                for number, when, record in split_records(payload):
                    self._put(route.key, record, wire.encode_attachment(number, when, gid))
            else:
                self._put(route.key, payload, wire.encode_attachment(seq, stamp, gid))
            return
        if routed and kind == Kind.REQUEST and route is not None:
            self._request(route, sender, endpoint, seq, stamp, payload)
            return
        if routed and kind in (Kind.RESPONSE, Kind.FAILURE) and flags & Flags.ADDRESSED:
            self._reply(kind, payload)
            return
        if kind == Kind.REPLAY and topic in self._cached:
            return  # late subscriptions query the topic's Zenoh cache instead
        try:
            self.session.put(f"{ROSL_PREFIX}/{self.domain}/{channel}", data)
        except Exception as err:  # zenoh.ZError: a closed session
            if not self._closed:
                raise BusError(f"Zenoh: cannot send: {err}") from None

    def _put(self, key: str, payload: Buffer, attachment: bytes) -> None:
        self._publisher(key).put(bytes(payload), attachment=attachment)

    def _publisher(self, key: str) -> Any:
        """The declared publisher of a data key (declared at its first message)."""
        publisher = self._publishers.get(key)
        if publisher is None:
            with self._lock:
                publisher = self._publishers.get(key)
                if publisher is None:
                    publisher = self.session.declare_publisher(key)
                    self._publishers[key] = publisher
        return publisher

    def direct_sender(
        self, topic: int, sender: int, endpoint: int, kind: int
    ) -> Callable[[Buffer, int, int], None] | None:
        """A writer's short way for plain messages (the seam's optional hook), or None.

        A publisher's message becomes a put on its topic's key with no rosl header made and
        read back: ``put(payload, seq, stamp)``. Other kinds, and topics without a key here,
        go through :meth:`send`.
        """
        route = self._routes.get(topic)
        if kind != Kind.DATA or route is None or not route.key or route.service:
            return None
        key, gid, pack = route.key, self.local.gid, wire.ATTACHMENT.pack
        size = wire.GID_SIZE

        def put(payload: Buffer, seq: int, stamp: int) -> None:
            if self._closed:
                return
            data = payload if type(payload) is bytes else bytes(payload)
            attachment = pack(seq, stamp, size, gid(sender, endpoint))
            self._publisher(key).put(data, attachment=attachment)

        return put

    def _request(
        self, route: _Route, sender: int, endpoint: int, seq: int, stamp: int, payload: Buffer
    ) -> None:
        import zenoh

        gid = self.local.gid(sender, endpoint)
        topic = hash_topic(route.name)
        type_ = hash_type(route.type)

        def on_reply(reply: zenoh.Reply) -> None:
            ok = reply.ok
            if ok is not None:
                kind, body = Kind.RESPONSE, ok.payload.to_bytes()
            else:
                kind, body = Kind.FAILURE, _failure(reply.err)
            now = time.time_ns()
            self._deliver(
                Delivery(
                    kind,
                    sender,
                    endpoint,
                    seq,
                    topic,
                    type_,
                    now,
                    now,
                    memoryview(body),
                    (sender, endpoint, seq),
                )
            )

        self.session.get(
            route.key, on_reply, target=zenoh.QueryTarget.ALL_COMPLETE,
            consolidation=zenoh.ConsolidationMode.NONE, payload=bytes(payload),
            attachment=wire.encode_attachment(seq, stamp, gid),
        )  # fmt: skip

    def _reply(self, kind: int, payload: memoryview) -> None:
        if len(payload) < ADDRESS_SIZE:
            return
        process, endpoint, correlation = ADDRESS.unpack_from(payload)
        with self._lock:
            pending = self._queries.pop((process, endpoint, correlation), None)
        if pending is None:
            return  # answered already, or the query timed out
        query, client_gid = pending
        body = bytes(payload[ADDRESS_SIZE:])
        if kind == Kind.FAILURE:
            query.reply_err(body)
        else:
            attachment = wire.encode_attachment(correlation, time.time_ns(), client_gid)
            query.reply(query.key_expr, body, attachment=attachment)
        query.drop()

    def _on_own_discovery(self, payload: bytes) -> None:
        try:
            message = json.loads(payload)
        except ValueError:
            return
        if not isinstance(message, dict):
            return
        if message.get("op") == "hello":
            self.identities.announce(int(str(message["process"]["sender"]), 16))
            self.local.update(message["process"])
        elif message.get("op") == "bye":
            self.local.update(None)
        elif message.get("op") == "query":
            self.foreign.answer(f"{message['sender']}:{message['qid']}")
        elif message.get("op") == "replay":
            self._query_history(message)

    def _query_history(self, message: dict[str, Any]) -> None:
        """A late transient-local subscription of this process: ask the topic's caches."""
        from rosl.bus.zenoh_history import query_history

        try:
            sender, endpoint = message["target"]
            target = (int(str(sender), 16), int(endpoint))
            name = str(message["topic"])
        except (KeyError, TypeError, ValueError):
            return
        query_history(self, name, target)

    def identity(self, gid: bytes) -> tuple[int, int]:
        """(process, endpoint) of a GID: a rosl endpoint's own ids, else derived from it."""
        owner = self.identities.owners.get(gid)
        if owner is not None:
            return owner
        return int.from_bytes(gid[:8], "little") | 1, int.from_bytes(gid[8:10], "little")

    # --- receiving ------------------------------------------------------------------------------

    def _on_rosl_datagram(self, sample: zenoh.Sample) -> None:
        channel = int(str(sample.key_expr).rsplit("/", 1)[1])
        self.inject(channel, sample.payload.to_bytes())

    def inject(self, channel: int, datagram: bytes) -> None:
        """Hand a rosl datagram to every receiver that joined ``channel``."""
        for receiver in self.receivers:
            if channel in receiver.channels:
                receiver.put_datagram(datagram)

    def key_hashes(self, keyexpr: str) -> tuple[int, int]:
        """Rosl's (topic, type) hashes of a data key (cached: computed once per key)."""
        hashes = self._key_hashes.get(keyexpr)
        if hashes is None:
            key = wire.parse_topic_key(keyexpr)
            hashes = (hash_topic(key.name), hash_type(key.type))
            if len(self._key_hashes) < 65536:
                self._key_hashes[keyexpr] = hashes
        return hashes

    def _on_query(self, query: zenoh.Query) -> None:
        try:
            topic, type_ = self.key_hashes(str(query.key_expr))
            attachment = query.attachment
            if attachment is None:
                raise ValueError("no attachment")
            attachment_bytes = attachment.to_bytes()
            seq, stamp, sender, endpoint = read_attachment(attachment_bytes)
        except ValueError:
            query.reply_err(b"rosl: a request needs rmw_zenoh's attachment")
            return
        gid = attachment_bytes[17:]
        seq &= 0xFFFFFFFF
        with self._lock:
            self._queries[(sender, endpoint, seq)] = (query, gid)
        body = query.payload.to_bytes() if query.payload is not None else b""
        self._deliver(
            Delivery(
                Kind.REQUEST,
                sender,
                endpoint,
                seq,
                topic,
                type_,
                stamp,
                time.time_ns(),
                memoryview(body),
            )
        )

    def _deliver(self, delivery: Delivery, want_all: bool | None = None) -> None:
        """Hand a delivery to the receivers of its channel (of one kind, when ``want_all``)."""
        channel = channel_of(delivery.topic)
        for receiver in self.receivers:
            if channel in receiver.channels and (
                want_all is None or receiver.reader.want_all is want_all
            ):
                receiver.put_delivery(delivery)

    # --- the seam -------------------------------------------------------------------------------

    def receiver(self) -> ZenohReceiver:
        """A new receiver with no channel joined."""
        receiver = ZenohReceiver(self)
        with self._lock:
            self.receivers = (*self.receivers, receiver)
        return receiver

    def forget(self, receiver: ZenohReceiver) -> None:
        """A receiver closed."""
        with self._lock:
            self.receivers = tuple(r for r in self.receivers if r is not receiver)

    def describe(self) -> str:
        """Where the traffic goes."""
        return f"Zenoh session {self.zid} (domain {self.domain})"

    def close(self) -> None:
        """Undeclare everything and close the session (idempotent)."""
        if self._closed:
            return
        self._closed = True
        for receiver in self.receivers:
            receiver.close()
        self.foreign.close()
        with contextlib.suppress(Exception):  # a closed session undeclared them already
            self.identities.close()
        self.local.update(None)
        with contextlib.suppress(Exception):  # closing at exit: nothing left to tell
            self.session.close()  # type: ignore[no-untyped-call]


def _close_before_threads_join(transport: ZenohTransport) -> None:
    """Close the session at exit before the interpreter waits for its threads.

    zenoh-python runs Python callbacks on threads of its own that end only when what they
    serve is undeclared: a program that never shuts rosl down (a script, a node killed by a
    Ctrl-C) would wait for them forever, before any atexit handler could close the session.
    """
    ref = weakref.ref(transport)

    def close() -> None:
        alive = ref()
        if alive is not None:
            alive.close()

    with contextlib.suppress(RuntimeError):  # the interpreter is shutting down already
        threading._register_atexit(close)  # type: ignore[attr-defined]  # as concurrent.futures


def _failure(err: Any) -> bytes:
    text = "the server failed"
    if err is not None:
        try:
            text = err.payload.to_string()
        except Exception:
            text = "the server failed (a reply error that is not text)"
    if text.startswith("{"):
        return text.encode()  # rosl's own failure payload (JSON)
    return json.dumps({"error": text}).encode()
