"""Service clients: requests out, responses matched by sequence number; every wait bounded.

A server whose callback raised answers with a failure, which fails the call at once.

Responses wait in the client's queue; the executor of the node takes them (completing the
futures) whatever the client's callback group is doing, so a callback may await
``call_async``. ``call`` works inside a callback too: it waits on the participant, which
queues everything else for the executor, and takes its own response.
"""

from __future__ import annotations

import threading
from collections import deque
from typing import TYPE_CHECKING, Any

from rosl.bus.header import Kind, topic_hash, type_hash
from rosl.bus.wire import Writer
from rosl.graph.records import CLIENT, EndpointRecord
from rosl.idl import registry
from rosl.idl.errors import InterfaceError
from rosl.node.callback_groups import Queued
from rosl.node.errors import NodeError
from rosl.node.service import failure_text
from rosl.node.task import Future

if TYPE_CHECKING:
    from collections.abc import Callable

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


class Client(Queued):
    """Calls one service (rclpy.client.Client)."""

    _ungrouped = True  # completing a future never waits for the client's group

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
        self._pending: dict[int, Future[Any]] = {}
        self._queue_in(deque())
        self._lock = threading.Lock()  # a response may be taken on another thread at once
        self._what = name
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

    def call_async(self, request: Any) -> Future[Any]:
        """Send a request; the returned Future completes with the response.

        When the server's callback raises, the future fails instead: ``exception()`` is a
        :class:`ServiceFailedError` and ``result()`` raises it.
        """
        expected = self.srv_type.Request.__msgtype__
        if getattr(request, "__msgtype__", None) != expected:
            raise TypeError(
                f"client of {self.srv_name} sends {expected}, not {type(request).__name__}"
            )
        future: Future[Any] = Future()
        payload = self._store.serialize(request)
        with self._lock:
            seq = self._writer.send(payload)
            self._pending[seq] = future
        return future

    def call(self, request: Any, timeout_sec: float | None = None) -> Any:
        """Send a request and wait for the response (safe inside callbacks).

        Raises:
            ServiceTimeoutError: no response within ``timeout_sec`` (None waits without limit)
                or the context was shut down meanwhile.
            ServiceFailedError: the server's callback raised (reported at once).
        """
        future = self.call_async(request)
        participant = self.node.participant
        context = self.node.context
        future.add_done_callback(lambda _: participant.notify())

        def answered() -> bool:
            while self._take() is not None:
                pass
            return future.done() or not context.ok()

        participant.wait(answered, timeout_sec)
        if not future.done():
            self.remove_pending_request(future)
            why = "before shutdown" if not context.ok() else f"within {timeout_sec} s"
            raise ServiceTimeoutError(f"service {self.srv_name} did not answer {why}")
        return future.result()

    def remove_pending_request(self, future: Future[Any]) -> None:
        """Forget a request whose response is no longer wanted."""
        with self._lock:
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
        """Queue a response to one of this client's requests (on the polling thread)."""
        if self._mine(delivery):
            self._queue.append(delivery)

    def _take(self) -> Callable[[], Any] | None:
        """Complete the future the oldest queued response answers (no callback to run)."""
        delivery = self._pop()
        if delivery is None:
            return None
        address = delivery.address
        with self._lock:
            future = None if address is None else self._pending.pop(address[2], None)
        if future is None:
            return None
        if delivery.kind == Kind.FAILURE:
            future.set_exception(ServiceFailedError(self.srv_name, failure_text(delivery.payload)))
            return None
        try:
            response = self._store.deserialize(delivery.payload, self.srv_type.Response.__msgtype__)
        except InterfaceError as err:
            future.set_exception(err)
            return None
        future.set_result(response)
        return None

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
