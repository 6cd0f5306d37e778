"""``rosl bridge foxglove``: the live bus as a Foxglove WebSocket server (foxglove_bridge's job).

Foxglove (and Lichtblick) open a running ROS 2 system through a WebSocket protocol that ROS 2's
``foxglove_bridge`` serves. rosl serves it through the ``foxglove-sdk`` package: its server is
native code (the one foxglove_bridge 3.x runs on), so rosl never frames the protocol itself and
follows the app as the SDK does. The SDK speaks the subprotocol ``foxglove.sdk.v1``, the new name
of ``foxglove.websocket.v1`` (same messages); a client offering only the old name is refused.

Everything goes through one participant, so the bridge works on any transport of the seam:

* each topic with a publisher (``--topics``: names fully matching a regular expression; hidden
  names left out) is a channel, encoding ``cdr``, schema the ``ros2msg`` text rosbag2 writes
  (from the .msg files this process reads; a type it cannot read is left out, said once).
  Channels come and go with the topic's publishers;
* a topic is listened to only while some client subscribes to its channel. The bridge's node
  (``/foxglove_bridge``) announces that subscription, so publishers that only compute what is
  read (the simulator) start sending, and stop when nobody watches. Each message's CDR bytes go
  out as they came, never decoded. A client subscribing to a transient-local topic
  (``/tf_static``) makes the bridge ask the publishers for their history again; the SDK cannot
  send to one client only, so the clients already subscribed get those messages once more;
* log time: the receive time (the recorder's ``log_time``, so a live view and a recording of one
  run agree, and the publisher's clock is not trusted). While a /clock publisher is on the bus
  (a simulator), log times are the sim time of the last /clock instead (0 before the first, as
  ROS 2's sim time). The server's time (broadcast a few dozen times a second) follows the same
  clock: Foxglove wants message times and the current time from one clock;
* clients may publish (``cdr``: the bytes go on the bus as they are), call the graph's services
  (request and response bytes forwarded, bounded waits) and get and set parameters named
  ``/node.param`` through the nodes' parameter services (updates from ``/parameter_events``).
"""

from __future__ import annotations

import collections
import re
import threading
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import foxglove
from foxglove.websocket import Capability, ServerListener

from rosl.bus.header import Kind, topic_hash, type_hash
from rosl.errors import RoslError
from rosl.graph.records import (
    CLIENT,
    PUBLISHER,
    SERVER,
    SUBSCRIPTION,
    EndpointRecord,
    NodeRecord,
    is_hidden,
)
from rosl.idl import registry
from rosl.idl.errors import InterfaceError
from rosl.introspection.foxglove_calls import BridgeError, Caller, Parameters

if TYPE_CHECKING:
    from collections.abc import Callable

    from foxglove.websocket import (
        ChannelView,
        Client,
        ClientChannel,
        ServiceRequest,
        WebSocketServer,
    )

    from rosl.bus.wire import Delivery, Writer
    from rosl.node.participant import Participant

NODE = "foxglove_bridge"
BACKLOG = 256  # messages queued per client before the oldest is dropped (the SDK's bound)
CALL_TIMEOUT_S = 5.0  # a forwarded service call waits this long for its answer
SINKS_WAIT_S = 5.0  # a first subscriber is registered in the SDK right after its callback
_DATA, _REPLAY = int(Kind.DATA), int(Kind.REPLAY)
_CLOCK, _CLOCK_TYPE = "/clock", "rosgraph_msgs/msg/Clock"
SIM_TIME_EVERY_NS = 20_000_000  # sim time is broadcast at most every 20 ms of wall time
WALL_TIME_EVERY_S = 0.05  # wall time (no simulator) every 50 ms; each is a control message


@dataclass(frozen=True, slots=True)
class BridgeOptions:
    """How to serve (``rosl bridge foxglove``'s options)."""

    port: int = 8765  # 0: any free port
    address: str = "127.0.0.1"
    topics: str | None = None  # a regular expression topic names must match entirely
    domain: int | str | None = None


def _ip_address(text: str) -> str:
    """An IP address to listen on (``localhost`` is 127.0.0.1); never a host name to look up.

    Raises:
        BridgeError: not an IP address (a name would need DNS, which may leave the host).
    """
    import ipaddress

    if text == "localhost":
        return "127.0.0.1"
    try:
        return str(ipaddress.ip_address(text))
    except ValueError:
        raise BridgeError(
            f"--address '{text}' is not an IP address (e.g. 127.0.0.1, 0.0.0.0 or ::1)"
        ) from None


class _Clock:
    """Where log times come from: receive times, or the simulator's /clock (``sim``)."""

    __slots__ = ("now_ns", "sent_ns", "sim")

    def __init__(self) -> None:
        self.sim = False
        self.now_ns = 0  # the last /clock time
        self.sent_ns = 0  # wall time of the last broadcast


@dataclass(eq=False, slots=True)
class _Channel:
    """One bus topic advertised to the clients."""

    name: str
    type_name: str
    channel: foxglove.Channel
    clock: _Clock
    sender: int  # this process (history is addressed to it)
    endpoint: int  # the bridge's subscription, announced while clients watch
    latched: bool  # a publisher keeps history for late subscribers
    qos: dict[str, Any]
    type: int = 0
    clients: set[int] = field(default_factory=set)
    targets: collections.deque[int] = field(default_factory=lambda: collections.deque(maxlen=64))
    forwarded: int = 0

    def __post_init__(self) -> None:
        self.type = type_hash(self.type_name)

    def deliver(self, delivery: Delivery) -> None:
        """Forward one message's bytes to the subscribed clients (on the polling thread)."""
        if delivery.type != self.type:
            return  # another type on the same topic: the channel has one schema
        if delivery.kind != _DATA:
            address = delivery.address
            if delivery.kind != _REPLAY or address is None or address[0] != self.sender:
                return
            if address[1] not in self.targets:
                return  # history someone else asked for
        clock = self.clock
        log_time = clock.now_ns if clock.sim else delivery.received
        self.channel.log(bytes(delivery.payload), log_time=log_time)
        self.forwarded += 1


@dataclass(slots=True)
class _Outlet:
    """A channel a client publishes on: a publisher on the bus."""

    topic: str
    type_name: str
    writer: Writer


class FoxgloveBridge:
    """A Foxglove WebSocket server over one domain: :meth:`start`, :meth:`run`, :meth:`close`."""

    def __init__(self, options: BridgeOptions, log: Callable[[str], None] | None = None) -> None:
        try:
            self._pattern = re.compile(options.topics) if options.topics is not None else None
        except re.error as err:
            raise BridgeError(
                f"--topics '{options.topics}' is no regular expression: {err}"
            ) from None
        self._address = _ip_address(options.address)
        self.options = options
        self._log = log or (lambda line: None)
        self.participant: Participant | None = None
        self.server: WebSocketServer | None = None
        self.url = ""
        self.clock = _Clock()
        self.parameters = Parameters(self)
        self._context = foxglove.Context()
        self._channels: dict[str, _Channel] = {}  # by topic
        self._by_id: dict[int, _Channel] = {}  # by channel id
        self._services: dict[str, str] = {}  # advertised service -> type
        self._callers: dict[str, Caller] = {}
        self._outlets: dict[tuple[int, int], _Outlet] = {}  # by (client, client channel)
        self._jobs: collections.deque[Callable[[], None]] = collections.deque()
        self._lock = threading.RLock()  # what the discovery and server threads read
        self._warned: set[str] = set()
        self._forwarded: dict[str, int] = {}  # messages sent, by topic (once unadvertised)
        self._synced = -1
        self._index = 0
        self._clock_tap: _ClockTap | None = None
        self._next_tick = 0.0  # when wall time is broadcast next (monotonic)
        self._stopping = False

    # --- lifecycle ---------------------------------------------------------------------------

    def start(self) -> str:
        """Join the bus, read the graph and start serving; return the server's URL.

        Raises:
            BridgeError: the address or port cannot be listened on.
        """
        from rosl.node.participant import Participant

        participant = self.participant = Participant(self.options.domain)
        try:
            self._index = participant.add_node(self._describe)
            discovery = participant.discovery
            discovery.wait_complete(discovery.query(), timeout=1.0)
            self.server = self._serve()
            self._sync()
            discovery.changed()
        except BaseException:
            self.close()
            raise
        return self.url

    def _serve(self) -> WebSocketServer:
        capabilities = [
            Capability.ClientPublish, Capability.Services, Capability.Parameters, Capability.Time
        ]  # fmt: skip
        address, port = self._address, self.options.port
        try:
            server = foxglove.start_server(
                name="rosl", host=address, port=port, capabilities=capabilities,
                server_listener=_Listener(self), supported_encodings=["cdr"],
                context=self._context, message_backlog_size=BACKLOG,
            )  # fmt: skip
        except (RuntimeError, OverflowError, ValueError) as err:
            reason = str(err).removeprefix("FoxgloveError: ").removeprefix("Failed to bind port: ")
            if "in use" in reason:
                reason = f"port {port} is in use (another bridge? pick another with --port)"
            raise BridgeError(f"cannot listen on {address} port {port}: {reason}") from None
        host = f"[{address}]" if ":" in address else address
        self.url = f"ws://{host}:{server.port}"
        return server

    def run(self, until: Callable[[], bool]) -> None:
        """Serve until ``until()`` is true or :meth:`stop` is called."""
        while not self._stopping and not until():
            self.step(0.1)

    def step(self, timeout: float = 0.1) -> None:
        """Do what clients asked, follow the graph, forward what arrives within ``timeout``."""
        participant = self.participant
        assert participant is not None
        while self._jobs:
            self._jobs.popleft()()
        if participant.graph.generation != self._synced:
            self._sync()
        now = time.monotonic()
        if not self.clock.sim and now >= self._next_tick and self.server is not None:
            self._next_tick = now + WALL_TIME_EVERY_S
            self.server.broadcast_time(time.time_ns())
        participant.poll(min(timeout, WALL_TIME_EVERY_S))

    def stop(self) -> None:
        """Ask :meth:`run` to return (safe in a signal handler)."""
        self._stopping = True
        if self.participant is not None:
            self.participant.notify()

    def later(self, job: Callable[[], None]) -> None:
        """Run ``job`` on the bridge's thread (from the server's threads)."""
        self._jobs.append(job)
        if self.participant is not None:
            self.participant.notify()

    def close(self) -> None:
        """Stop serving and leave the bus (idempotent); log what was forwarded."""
        self._stopping = True
        with self._lock:
            callers = list(self._callers.values())
        for caller in callers:
            caller.cancel()
        if self.server is not None:
            self.server.stop()
            self.server = None
            for name in list(self._channels):
                self._unadvertise(name)
            forwarded = sum(self._forwarded.values())
            watched = sum(1 for count in self._forwarded.values() if count)
            self._log(f"[INFO] [{NODE}]: stopped: {forwarded} messages forwarded on "
                      f"{watched} topics")  # fmt: skip
        if self.participant is not None:
            self.participant.close()

    # --- the graph ---------------------------------------------------------------------------

    def _publishers(self, name: str) -> list[EndpointRecord]:
        assert self.participant is not None
        own = self.participant.sender
        graph = self.participant.graph
        return [e for node, e in graph.endpoints(PUBLISHER, name) if node.process != own]

    def _sync(self) -> None:
        """Advertise the graph's topics and services as they are now."""
        participant = self.participant
        assert participant is not None
        graph = participant.graph
        self._synced = graph.generation
        topics: dict[str, list[EndpointRecord]] = {}
        services: dict[str, str] = {}
        for node, endpoint in graph.endpoints():
            if node.process == participant.sender or is_hidden(endpoint.name):
                continue
            if endpoint.kind == PUBLISHER and self._wanted(endpoint.name):
                topics.setdefault(endpoint.name, []).append(endpoint)
            elif endpoint.kind == SERVER:
                services.setdefault(endpoint.name, endpoint.type)
        for name in [n for n in self._channels if n not in topics]:
            self._unadvertise(name)
        for name, publishers in sorted(topics.items()):
            if name not in self._channels:
                self._advertise(name, publishers)
        self._sync_services(services)
        self._follow_clock(bool(self._publishers(_CLOCK)))

    def _follow_clock(self, sim: bool) -> None:
        """Take log times and the server's time from /clock while someone publishes it."""
        clock, participant = self.clock, self.participant
        assert participant is not None
        if sim == clock.sim:
            return
        if sim:
            clock.now_ns = 0
            self._clock_tap = _ClockTap(self, participant.next_endpoint())
            participant.listen(topic_hash(_CLOCK), self._clock_tap)
        elif self._clock_tap is not None:
            participant.unlisten(topic_hash(_CLOCK), self._clock_tap)
            self._clock_tap = None
        clock.sim = sim
        participant.discovery.changed()

    def _wanted(self, name: str) -> bool:
        return self._pattern is None or self._pattern.fullmatch(name) is not None

    def _advertise(self, name: str, publishers: list[EndpointRecord]) -> None:
        assert self.participant is not None
        types = sorted({e.type for e in publishers})
        type_name = types[0]
        if len(types) > 1:
            self.warn_once(f"types {name}", f"{name} has publishers of several types "
                           f"({', '.join(types)}): advertised as {type_name}")  # fmt: skip
        try:
            text = registry.msgdef_text(type_name)
        except InterfaceError:
            self.warn_once(f"unknown {name}", f"{name}: type {type_name} is unknown here (no "
                           ".msg file on the interface path): not advertised")  # fmt: skip
            return
        durable = [
            str(e.qos.get("durability", "")).upper() == "TRANSIENT_LOCAL" for e in publishers
        ]
        reliable = all(str(e.qos.get("reliability", "")).upper() == "RELIABLE" for e in publishers)
        qos = {"reliability": "RELIABLE" if reliable else "BEST_EFFORT",
               "durability": "TRANSIENT_LOCAL" if all(durable) else "VOLATILE",
               "history": "KEEP_LAST", "depth": 10}  # fmt: skip
        schema = foxglove.Schema(name=type_name, encoding="ros2msg", data=text.encode())
        channel = foxglove.Channel(
            name, schema=schema, message_encoding="cdr", context=self._context
        )
        advertised = _Channel(
            name, type_name, channel, self.clock, self.participant.sender,
            self.participant.next_endpoint(), any(durable), qos,
        )  # fmt: skip
        with self._lock:
            self._channels[name] = advertised
            self._by_id[channel.id()] = advertised

    def _unadvertise(self, name: str) -> None:
        with self._lock:
            advertised = self._channels.pop(name)
            self._by_id.pop(advertised.channel.id(), None)
        self._forwarded[name] = self._forwarded.get(name, 0) + advertised.forwarded
        if advertised.clients:
            self._stop_listening(advertised)
        advertised.channel.close()  # the SDK unsubscribes the clients and unadvertises it

    def _sync_services(self, services: dict[str, str]) -> None:
        assert self.server is not None
        gone = [n for n, t in self._services.items() if services.get(n) != t]
        for name in gone:
            del self._services[name]
        if gone:
            self.server.remove_services(gone)
        added = []
        for name, type_name in sorted(services.items()):
            if name in self._services:
                continue
            schema = self._service_schema(name, type_name)
            if schema is not None:
                added.append(foxglove.Service(
                    name, schema=schema, handler=self._forwarder(name, type_name)
                ))  # fmt: skip
            self._services[name] = type_name
        if added:
            self.server.add_services(added)

    def _service_schema(self, name: str, type_name: str) -> foxglove.ServiceSchema | None:
        parts = []
        try:
            for part in ("Request", "Response"):
                text = registry.msgdef_text(f"{type_name}_{part}")
                schema = foxglove.Schema(
                    name=f"{type_name}_{part}", encoding="ros2msg", data=text.encode()
                )
                parts.append(foxglove.MessageSchema(encoding="cdr", schema=schema))
        except InterfaceError:
            self.warn_once(f"unknown {name}", f"service {name}: type {type_name} is unknown "
                           "here: not advertised")  # fmt: skip
            return None
        return foxglove.ServiceSchema(type_name, request=parts[0], response=parts[1])

    def _forwarder(self, name: str, type_name: str) -> Callable[[ServiceRequest], bytes]:
        def forward(request: ServiceRequest) -> bytes:  # on one of the SDK's threads
            return self.caller(name, type_name).call(request.payload, CALL_TIMEOUT_S)

        return forward

    def caller(self, name: str, type_name: str) -> Caller:
        """The byte client of a service (made and announced on first use, from any thread)."""
        assert self.participant is not None
        with self._lock:
            found = self._callers.get(name)
            if found is None or found.type_name != type_name:
                found = self._callers[name] = Caller(self.participant, name, type_name)
                self.participant.discovery.changed()
        return found

    # --- clients' subscriptions (on the bridge's thread) --------------------------------------

    def subscribe(self, client: int, channel_id: int) -> None:
        """A client subscribed to a channel: listen to its topic (ask for history if kept)."""
        advertised = self._by_id.get(channel_id)
        if advertised is None:
            return
        first = not advertised.clients
        with self._lock:
            advertised.clients.add(client)
        assert self.participant is not None
        if first:
            self.participant.listen(topic_hash(advertised.name), advertised)
            self.participant.discovery.changed()
        if advertised.latched:
            deadline = time.monotonic() + SINKS_WAIT_S
            while not advertised.channel.has_sinks() and time.monotonic() < deadline:
                time.sleep(0.001)  # the SDK adds the client right after on_subscribe returns
            target = self.participant.next_endpoint()
            advertised.targets.append(target)
            self.participant.discovery.send({
                "op": "replay", "topic": advertised.name,
                "target": [f"{self.participant.sender:016x}", target],
            })  # fmt: skip

    def unsubscribe(self, client: int, channel_id: int) -> None:
        """A client unsubscribed (or left): stop listening once nobody watches."""
        advertised = self._by_id.get(channel_id)
        if advertised is None or client not in advertised.clients:
            return
        with self._lock:
            advertised.clients.discard(client)
        if not advertised.clients:
            self._stop_listening(advertised)

    def _stop_listening(self, advertised: _Channel) -> None:
        assert self.participant is not None
        with self._lock:
            advertised.clients.clear()
        self.participant.unlisten(topic_hash(advertised.name), advertised)
        self.participant.discovery.changed()

    # --- clients' publishers (on the server's threads) ---------------------------------------

    def advertise_outlet(self, client: int, channel: ClientChannel) -> None:
        """A client advertised a channel: a publisher of its topic and type on the bus."""
        from rosl.bus.wire import Writer
        from rosl.idl.names import canonical

        assert self.participant is not None
        if channel.encoding != "cdr":
            self.warn(f"client channel {channel.topic}: encoding {channel.encoding} is not "
                      "supported (only cdr): ignored")  # fmt: skip
            return
        try:
            type_name = canonical(channel.schema_name, "msg")
        except InterfaceError as err:
            self.warn(f"client channel {channel.topic}: {err}: ignored")
            return
        topic = "/" + channel.topic.lstrip("/")
        participant = self.participant
        writer = Writer(
            participant.transport, participant.sender, participant.next_endpoint(), topic,
            type_name,
        )  # fmt: skip
        with self._lock:
            self._outlets[(client, channel.id)] = _Outlet(topic, type_name, writer)
        participant.discovery.changed()

    def publish(self, client: int, channel_id: int, data: bytes) -> None:
        """Send a client's message bytes on the bus as they are."""
        outlet = self._outlets.get((client, channel_id))
        if outlet is None:
            return
        try:
            outlet.writer.send(data)
        except RoslError as err:
            self.warn(f"cannot publish on {outlet.topic}: {err}")

    def unadvertise_outlet(self, client: int, channel_id: int) -> None:
        """A client stopped publishing on a channel (or left)."""
        with self._lock:
            found = self._outlets.pop((client, channel_id), None)
        if found is not None and self.participant is not None:
            self.participant.discovery.changed()

    # --- the bridge in the graph, and its messages -------------------------------------------

    def _describe(self) -> NodeRecord:  # on the discovery thread
        assert self.participant is not None
        with self._lock:
            watched = [c for c in self._channels.values() if c.clients]
            outlets = list(self._outlets.values())
            callers = list(self._callers.values())
        endpoints = [
            EndpointRecord(SUBSCRIPTION, c.name, c.type_name, c.endpoint, dict(c.qos),
                           {"received": c.forwarded})
            for c in watched
        ]  # fmt: skip
        endpoints += self.parameters.endpoints()
        tap = self._clock_tap
        if tap is not None:
            qos = {"reliability": "RELIABLE", "durability": "VOLATILE", "depth": 1}
            endpoints.append(EndpointRecord(SUBSCRIPTION, _CLOCK, _CLOCK_TYPE, tap.endpoint, qos))
        qos = {"reliability": "RELIABLE", "durability": "VOLATILE", "depth": 10}
        endpoints += [
            EndpointRecord(PUBLISHER, o.topic, o.type_name, o.writer.endpoint, dict(qos),
                           {"sent": o.writer.sent})
            for o in outlets
        ]  # fmt: skip
        endpoints += [EndpointRecord(CLIENT, c.name, c.type_name, c.endpoint) for c in callers]
        return NodeRecord(NODE, "/", self.participant.sender, self._index, tuple(endpoints))

    def warn(self, text: str) -> None:
        """Log one warning line."""
        self._log(f"[WARN] [{NODE}]: {text}")

    def warn_once(self, key: str, text: str) -> None:
        """Log a warning the first time ``key`` comes up."""
        if key not in self._warned:
            self._warned.add(key)
            self.warn(text)


class _ClockTap:
    """Follows /clock (sim time): the log time of what is forwarded, and the server's time."""

    def __init__(self, bridge: FoxgloveBridge, endpoint: int) -> None:
        self._bridge = bridge
        self.endpoint = endpoint
        self._type = type_hash(_CLOCK_TYPE)
        self._store = registry.store()
        registry.get_message_class(_CLOCK_TYPE)  # the store decodes only loaded types

    def deliver(self, delivery: Delivery) -> None:
        """Take one /clock message (on the polling thread)."""
        if delivery.kind != _DATA or delivery.type != self._type:
            return
        try:
            message: Any = self._store.deserialize(delivery.payload, _CLOCK_TYPE)
        except InterfaceError:
            return
        clock, stamp = self._bridge.clock, message.clock
        clock.now_ns = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
        server = self._bridge.server
        if server is not None and delivery.received - clock.sent_ns >= SIM_TIME_EVERY_NS:
            clock.sent_ns = delivery.received
            server.broadcast_time(clock.now_ns)


class _Listener(ServerListener):
    """The SDK's callbacks (on its threads): quick ones hand work to the bridge's thread."""

    def __init__(self, bridge: FoxgloveBridge) -> None:
        self._bridge = bridge

    def on_subscribe(self, client: Client, channel: ChannelView) -> None:
        """Listen to the channel's topic (on the bridge's thread)."""
        self._bridge.later(lambda: self._bridge.subscribe(client.id, channel.id))

    def on_unsubscribe(self, client: Client, channel: ChannelView) -> None:
        """Stop listening once nobody watches (on the bridge's thread)."""
        self._bridge.later(lambda: self._bridge.unsubscribe(client.id, channel.id))

    def on_client_advertise(self, client: Client, channel: ClientChannel) -> None:
        """Make a publisher for the client's channel."""
        self._bridge.advertise_outlet(client.id, channel)

    def on_client_unadvertise(self, client: Client, client_channel_id: int) -> None:
        """Drop the client channel's publisher."""
        self._bridge.unadvertise_outlet(client.id, client_channel_id)

    def on_message_data(self, client: Client, client_channel_id: int, data: bytes) -> None:
        """Publish the client's bytes."""
        self._bridge.publish(client.id, client_channel_id, data)

    def on_get_parameters(
        self, client: Client, param_names: list[str], request_id: str | None = None
    ) -> list[foxglove.Parameter]:
        """Read parameters from the nodes (all of them for an empty list)."""
        return self._bridge.parameters.get(param_names)

    def on_set_parameters(
        self, client: Client, parameters: list[foxglove.Parameter], request_id: str | None = None
    ) -> list[foxglove.Parameter]:
        """Set parameters on their nodes; return their values afterwards."""
        return self._bridge.parameters.set(parameters)

    def on_parameters_subscribe(self, param_names: list[str]) -> None:
        """Send these parameters' changes to the clients from now on."""
        self._bridge.later(lambda: self._bridge.parameters.watch(param_names, True))

    def on_parameters_unsubscribe(self, param_names: list[str]) -> None:
        """Stop sending these parameters' changes."""
        self._bridge.later(lambda: self._bridge.parameters.watch(param_names, False))
