"""The Foxglove bridge's calls into the graph: service calls and parameters, as bytes.

Split from ``foxglove_bridge.py`` (one module, one job): :class:`Caller` sends a service
request's CDR bytes and waits (bounded) for the response's bytes, never decoding either;
:class:`Parameters` gets and sets parameters named ``/node.param`` through each node's
rcl_interfaces services in parallel, and turns ``/parameter_events`` into updates for
subscribed clients.
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING, Any

import foxglove

from rosl.bus.header import Kind, topic_hash, type_hash
from rosl.errors import RoslError
from rosl.graph.records import SERVER, SUBSCRIPTION, EndpointRecord
from rosl.idl import registry
from rosl.idl.errors import InterfaceError
from rosl.introspection.errors import IntrospectionError
from rosl.node.parameters import Parameter, ParameterType, value_from_msg

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.wire import Delivery
    from rosl.introspection.foxglove_bridge import FoxgloveBridge
    from rosl.node.participant import Participant

_DATA = int(Kind.DATA)
_ANSWERS = (int(Kind.RESPONSE), int(Kind.FAILURE))
_EVENTS, _EVENT_TYPE = "/parameter_events", "rcl_interfaces/msg/ParameterEvent"
PARAMETER_TIMEOUT_S = 2.0  # the nodes' parameter services answer within this, or are left out


class BridgeError(IntrospectionError):
    """The bridge cannot start (a bad option, an address or port it cannot listen on)."""


class _Reply:
    """The answer to one forwarded request, filled on the polling thread."""

    __slots__ = ("data", "done", "failed")

    def __init__(self) -> None:
        self.done = threading.Event()
        self.failed = False
        self.data = b""


class Caller:
    """A client of one service that sends and receives bytes (requests are not decoded)."""

    def __init__(self, participant: Participant, name: str, type_name: str) -> None:
        from rosl.bus.wire import Writer

        self.name = name
        self.type_name = type_name
        self.endpoint = participant.next_endpoint()
        self._sender = participant.sender
        self._writer = Writer(
            participant.transport, participant.sender, self.endpoint, name, type_name,
            Kind.REQUEST,
        )  # fmt: skip
        self._pending: dict[int, _Reply] = {}
        self._lock = threading.Lock()
        participant.listen(topic_hash(name), self)

    def send(self, payload: bytes) -> tuple[int, _Reply]:
        """Send a request; return its number and the reply to wait for."""
        reply = _Reply()
        with self._lock:  # registered before an answer can be taken
            seq = self._writer.send(payload)
            self._pending[seq] = reply
        return seq, reply

    def wait(self, seq: int, reply: _Reply, deadline: float) -> bytes:
        """The response bytes of a request sent with :meth:`send`.

        Raises:
            BridgeError: no answer by ``deadline`` (monotonic), or the server's callback failed.
        """
        if not reply.done.wait(max(0.0, deadline - time.monotonic())):
            with self._lock:
                self._pending.pop(seq, None)
            raise BridgeError(f"service {self.name} did not answer in time")
        if reply.failed:
            from rosl.node.service import failure_text

            raise BridgeError(f"service {self.name} failed: {failure_text(reply.data)}")
        return reply.data

    def call(self, payload: bytes, timeout: float) -> bytes:
        """Send one request and wait (at most ``timeout`` s) for the response bytes."""
        seq, reply = self.send(payload)
        return self.wait(seq, reply, time.monotonic() + timeout)

    def deliver(self, delivery: Delivery) -> None:
        """Take an answer addressed to this client (on the polling thread)."""
        address = delivery.address
        if delivery.kind not in _ANSWERS or address is None:
            return
        if address[0] != self._sender or address[1] != self.endpoint:
            return
        with self._lock:
            reply = self._pending.pop(address[2], None)
        if reply is not None:
            reply.failed = delivery.kind != _ANSWERS[0]
            reply.data = bytes(delivery.payload)
            reply.done.set()

    def cancel(self) -> None:
        """Fail every waiting request at once (the bridge stops)."""
        with self._lock:
            pending, self._pending = self._pending, {}
        for reply in pending.values():
            reply.failed, reply.data = True, b"the bridge stopped"
            reply.done.set()


class Parameters:
    """Foxglove's parameters (``/node.param``) through the nodes' rcl_interfaces services."""

    def __init__(self, bridge: FoxgloveBridge) -> None:
        self._bridge = bridge
        self.watched: set[str] = set()  # names clients want the changes of
        self._events: _EventTap | None = None

    def get(self, names: list[str]) -> list[foxglove.Parameter]:
        """The values of ``names`` (every node's parameters for an empty list)."""
        if names:
            wanted = _by_node(names)
        else:
            nodes = self._nodes()
            listed = self._call(nodes, "list_parameters", lambda node: {"depth": 0})
            wanted = {node: list(answer.result.names) for node, answer in listed.items()}
        answers = self._call(list(wanted), "get_parameters", lambda node: {"names": wanted[node]})
        found = []
        for node, answer in answers.items():
            for name, value in zip(wanted[node], answer.values, strict=False):
                parameter = to_foxglove(f"{node}.{name}", value)
                if parameter is not None:
                    found.append(parameter)
        return found

    def set(self, parameters: list[foxglove.Parameter]) -> list[foxglove.Parameter]:
        """Set parameters on their nodes; return their values afterwards."""
        messages: dict[str, list[Any]] = {}
        for parameter in parameters:
            node, dot, name = parameter.name.partition(".")
            try:
                if not (dot and node.startswith("/") and name):
                    raise BridgeError("parameter names are /node.name")
                messages.setdefault(node, []).append(from_foxglove(name, parameter))
            except RoslError as err:
                self._bridge.warn(f"cannot set {parameter.name}: {err}")
        answers = self._call(list(messages), "set_parameters",
                             lambda node: {"parameters": messages[node]})  # fmt: skip
        for node, answer in answers.items():
            for result, message in zip(answer.results, messages[node], strict=False):
                if not result.successful:
                    self._bridge.warn(f"cannot set {node}.{message.name}: {result.reason}")
        return self.get([p.name for p in parameters])

    def _nodes(self) -> list[str]:
        """The nodes that serve parameters (not this bridge)."""
        participant = self._bridge.participant
        assert participant is not None
        graph = participant.graph
        return sorted({
            e.name.removesuffix("/list_parameters") for node, e in graph.endpoints(SERVER)
            if e.name.endswith("/list_parameters") and node.process != participant.sender
        })  # fmt: skip

    def _call(
        self, nodes: list[str], service: str, values: Callable[[str], dict[str, Any]]
    ) -> dict[str, Any]:
        """Call ``<node>/<service>`` of every node at once; the answers that came in time."""
        srv_name = "rcl_interfaces/srv/" + "".join(p.capitalize() for p in service.split("_"))
        srv = registry.get_service_class(srv_name)
        store = registry.store()
        graph = self._bridge.participant.graph if self._bridge.participant else None
        sent = []
        for node in nodes:
            if graph is None or not graph.has_server(f"{node}/{service}"):
                self._bridge.warn(f"parameters of {node}: no node serves {node}/{service}")
                continue
            caller = self._bridge.caller(f"{node}/{service}", srv_name)
            sent.append((node, caller, *caller.send(store.serialize(srv.Request(**values(node))))))
        deadline = time.monotonic() + PARAMETER_TIMEOUT_S
        answers = {}
        for node, caller, seq, reply in sent:
            try:
                data = caller.wait(seq, reply, deadline)
                answers[node] = store.deserialize(data, srv.Response.__msgtype__)
            except (BridgeError, InterfaceError) as err:
                self._bridge.warn(f"parameters of {node}: {err}")
        return answers

    def watch(self, names: list[str], on: bool) -> None:
        """Start or stop sending changes of ``names`` (on the bridge's thread)."""
        participant = self._bridge.participant
        assert participant is not None
        if on:
            self.watched.update(names)
        else:
            self.watched.difference_update(names)
        if self.watched and self._events is None:
            self._events = _EventTap(self, participant.next_endpoint())
            participant.listen(topic_hash(_EVENTS), self._events)
        elif not self.watched and self._events is not None:
            participant.unlisten(topic_hash(_EVENTS), self._events)
            self._events = None
        participant.discovery.changed()

    def endpoints(self) -> list[EndpointRecord]:
        """The bridge's /parameter_events subscription, while clients watch parameters."""
        events = self._events
        if events is None:
            return []
        qos = {"reliability": "RELIABLE", "durability": "VOLATILE", "depth": 1000}
        return [EndpointRecord(SUBSCRIPTION, _EVENTS, _EVENT_TYPE, events.endpoint, qos)]

    def changed(self, event: Any) -> None:
        """Send the watched parameters a ParameterEvent sets (on the polling thread)."""
        server = self._bridge.server
        updates = []
        for message in [*event.new_parameters, *event.changed_parameters]:
            name = f"{event.node}.{message.name}"
            if name in self.watched:
                parameter = to_foxglove(name, message.value)
                if parameter is not None:
                    updates.append(parameter)
        if updates and server is not None:
            server.publish_parameter_values(updates)


class _EventTap:
    """The bridge's /parameter_events subscription."""

    def __init__(self, parameters: Parameters, endpoint: int) -> None:
        self._parameters = parameters
        self.endpoint = endpoint
        self._type = type_hash(_EVENT_TYPE)
        self._store = registry.store()
        registry.get_message_class(_EVENT_TYPE)

    def deliver(self, delivery: Delivery) -> None:
        """Take one parameter event (on the polling thread)."""
        if delivery.kind != _DATA or delivery.type != self._type:
            return
        try:
            event = self._store.deserialize(delivery.payload, _EVENT_TYPE)
        except InterfaceError:
            return
        self._parameters.changed(event)


def _by_node(names: list[str]) -> dict[str, list[str]]:
    """Parameter names (``/node.param``) grouped by node; names without a node are dropped."""
    grouped: dict[str, list[str]] = {}
    for full in names:
        node, dot, name = full.partition(".")
        if dot and node.startswith("/") and name:
            grouped.setdefault(node, []).append(name)
    return grouped


_HINTS = {
    ParameterType.DOUBLE: foxglove.ParameterType.Float64,
    ParameterType.DOUBLE_ARRAY: foxglove.ParameterType.Float64Array,
    ParameterType.BYTE_ARRAY: foxglove.ParameterType.ByteArray,
}


def to_foxglove(name: str, value: Any) -> foxglove.Parameter | None:
    """An rcl_interfaces/msg/ParameterValue as a Foxglove parameter (None when not set)."""
    kind, native = value_from_msg(value)
    if kind is ParameterType.NOT_SET:
        return None
    return foxglove.Parameter(name, value=native, type=_HINTS.get(kind))


def from_foxglove(name: str, parameter: foxglove.Parameter) -> Any:
    """A Foxglove parameter as an rcl_interfaces/msg/Parameter named ``name``.

    Raises:
        RoslError: a value ROS 2 parameters cannot hold (a dict, a mixed list).
    """
    value = parameter.get_value()
    if parameter.type is foxglove.ParameterType.Float64 and isinstance(value, int):
        value = float(value)
    elif parameter.type is foxglove.ParameterType.Float64Array and isinstance(value, list):
        value = [float(v) for v in value if isinstance(v, (int, float))]
    return Parameter(name, value=value).to_parameter_msg()
