"""Service clients: requests out, responses matched by sequence number; every wait bounded.

A server whose callback raised answers with a failure, which fails the call at once.

``call`` works inside a callback too: it reads only its own channel while it waits and
queues anything else it reads for the executor, so nothing deadlocks and nothing is lost.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from rosl.bus.header import Kind, topic_hash, type_hash
from rosl.bus.wire import Writer
from rosl.executor import Future
from rosl.graph.records import CLIENT, EndpointRecord
from rosl.idl import registry
from rosl.idl.errors import InterfaceError
from rosl.node.errors import NodeError
from rosl.node.service import failure_text

if TYPE_CHECKING:
    from rosl.bus.wire import Delivery
    from rosl.idl.messages import ServiceType
    from rosl.node.node import Node


_ANSWERS = (Kind.RESPONSE, Kind.FAILURE)


class ServiceTimeoutError(NodeError, TimeoutError):
    """A service did not become available, or did not answer, in time."""


class ServiceFailedError(NodeError, RuntimeError):
    """The server's callback raised while handling the request (the server says which error)."""

    def __init__(self, service: str, error: str) -> None:
        super().__init__(f"service {service} failed: {error}")
        self.service = service
        self.error = error  # "ZeroDivisionError: division by zero"


class Client:
    """Calls one service (rclpy.client.Client)."""

    def __init__(self, node: Node, srv_type: type[ServiceType], name: str) -> None:
        self.node = node
        self.srv_type = srv_type
        self.srv_name = name
        self.type_name = srv_type.__srvtype__
        participant = node.participant
        self.endpoint = participant.next_endpoint()
        self._sender = participant.sender
        self._topic = topic_hash(name)
        self._type = type_hash(self.type_name)
        self._writer = Writer(
            participant.transport, participant.sender, self.endpoint, name, self.type_name,
            Kind.REQUEST,
        )  # fmt: skip
        self._store = registry.store()
        self._pending: dict[int, Future] = {}
        self.destroyed = False
        participant.listen(self._topic, self)

    # --- availability ------------------------------------------------------------------------

    def service_is_ready(self) -> bool:
        """Whether a server for this service is in the graph."""
        return self.node.participant.graph.has_server(self.srv_name)

    def wait_for_service(self, timeout_sec: float | None = None) -> bool:
        """Block until a server exists (None: no limit, as in rclpy); return whether it does."""
        graph = self.node.participant.graph
        return graph.wait_for(lambda: graph.has_server(self.srv_name), timeout_sec)

    # --- calling -----------------------------------------------------------------------------

    def call_async(self, request: Any) -> Future:
        """Send a request; the returned Future completes with the response.

        When the server's callback raises, the future fails instead: ``exception()`` is a
        :class:`ServiceFailedError` and ``result()`` raises it.
        """
        expected = self.srv_type.Request.__msgtype__
        if getattr(request, "__msgtype__", None) != expected:
            raise TypeError(
                f"client of {self.srv_name} sends {expected}, not {type(request).__name__}"
            )
        future = Future()
        seq = self._writer.send(self._store.serialize(request))
        self._pending[seq] = future
        return future

    def call(self, request: Any, timeout_sec: float | None = None) -> Any:
        """Send a request and wait for the response (safe inside callbacks).

        Raises:
            ServiceTimeoutError: no response within ``timeout_sec`` (None waits without limit).
            ServiceFailedError: the server's callback raised (reported at once).
        """
        future = self.call_async(request)
        deadline = None if timeout_sec is None else time.monotonic() + timeout_sec
        participant = self.node.participant
        while not future.done():
            remaining = 0.05 if deadline is None else min(0.05, deadline - time.monotonic())
            if remaining <= 0:
                self.remove_pending_request(future)
                raise ServiceTimeoutError(
                    f"service {self.srv_name} did not answer within {timeout_sec} s"
                )
            others = []
            for delivery in participant.read_channel(self._topic, remaining):
                if delivery.topic == self._topic and self._mine(delivery):
                    self.deliver(delivery)
                else:
                    others.append(delivery)
            if others:
                participant.defer(others)
        return future.result()

    def remove_pending_request(self, future: Future) -> None:
        """Forget a request whose response is no longer wanted."""
        for seq, pending in list(self._pending.items()):
            if pending is future:
                del self._pending[seq]

    def _mine(self, delivery: Delivery) -> bool:
        address = delivery.address
        return (
            delivery.kind in _ANSWERS
            and address is not None
            and address[0] == self._sender
            and address[1] == self.endpoint
        )

    def deliver(self, delivery: Delivery) -> None:
        """Complete the future of the request this response answers."""
        if not self._mine(delivery) or delivery.address is None:
            return
        future = self._pending.pop(delivery.address[2], None)
        if future is None:
            return
        if delivery.kind == Kind.FAILURE:
            future.set_exception(ServiceFailedError(self.srv_name, failure_text(delivery.payload)))
            return
        try:
            response = self._store.deserialize(delivery.payload, self.srv_type.Response.__msgtype__)
        except InterfaceError as err:
            future.set_exception(err)
            return
        future.set_result(response)

    def record(self) -> EndpointRecord:
        """This client as discovery announces it."""
        return EndpointRecord(CLIENT, self.srv_name, self.type_name, self.endpoint)

    def close(self) -> None:
        """Stop listening for responses."""
        self.destroyed = True
        self.node.participant.unlisten(self._topic, self)

    def destroy(self) -> None:
        """rclpy: node.destroy_client."""
        self.node.destroy_client(self)
