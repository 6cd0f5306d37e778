"""Service servers: requests in, the callback's response out, addressed to the caller.

When the callback raises, the caller gets a ``Kind.FAILURE`` answer instead (JSON: the
exception's type and message), so it fails at once rather than waiting out its timeout; the
exception is logged with the node's name and the server keeps serving. Observers of service
traffic (recorders, ``service echo``) see only requests and responses.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import json
from collections import deque
from typing import TYPE_CHECKING, Any

from rosl.bus.header import Kind, topic_hash, type_hash
from rosl.bus.wire import Writer
from rosl.errors import RoslError
from rosl.graph.records import SERVER, EndpointRecord
from rosl.idl import registry
from rosl.idl.errors import InterfaceError
from rosl.node.callback_groups import Queued

if TYPE_CHECKING:
    import mmap
    from collections.abc import Callable, Coroutine

    from rosl.bus.wire import Delivery
    from rosl.idl.messages import ServiceType
    from rosl.node.node import Node


def failure_payload(err: BaseException) -> bytes:
    """A FAILURE answer's payload: the exception's type and message as JSON."""
    return json.dumps({"type": type(err).__name__, "message": str(err)}).encode()


def failure_text(payload: bytes | bytearray | memoryview | mmap.mmap) -> str:
    """``ZeroDivisionError: division by zero`` from a FAILURE payload (whatever it holds)."""
    try:
        data = json.loads(bytes(payload))
        kind, message = str(data["type"]), str(data["message"])
    except (ValueError, TypeError, KeyError):
        return bytes(payload).decode("utf-8", "replace") or "unknown error"
    return f"{kind}: {message}" if message else kind


REQUESTS_KEPT = 4096  # requests waiting for the callback before the oldest is dropped


_REQUEST = int(Kind.REQUEST)


class Service(Queued):
    """Serves one service name (rclpy.service.Service); the callback may be a coroutine."""

    def __init__(
        self,
        node: Node,
        srv_type: type[ServiceType],
        name: str,
        callback: Callable[[Any, Any], Any],
    ) -> None:
        self.node = node
        self.srv_type = srv_type
        self.service_name = name
        self.callback = callback
        self.type_name = srv_type.__srvtype__
        participant = node.participant
        self.endpoint = participant.next_endpoint()
        self._topic = topic_hash(name)
        self._type = type_hash(self.type_name)
        self._writer = Writer(
            participant.transport, participant.sender, self.endpoint, name, self.type_name,
            Kind.RESPONSE,
        )  # fmt: skip
        self._store = registry.store()
        self.handled = 0
        self.destroyed = False
        self._queue_in(deque(maxlen=REQUESTS_KEPT))
        self._what = name
        participant.listen(self._topic, self)

    def deliver(self, delivery: Delivery) -> None:
        """Queue one request for the executor (on the polling thread)."""
        if delivery.kind == _REQUEST and not self.destroyed:
            self._queue.append(delivery)

    def _take(self) -> Callable[[], Any] | None:
        """Take the oldest request: the call that answers it."""
        delivery = self._pop()
        if delivery is None:
            return None
        if delivery.type != self._type:
            self.node.get_logger().warn(
                f"service {self.service_name} ({self.type_name}) got a request of another "
                "type; ignored",
                once=True,
            )
            return None
        try:
            request = self._store.deserialize(delivery.payload, self.srv_type.Request.__msgtype__)
        except InterfaceError as err:
            self.node.get_logger().warn(f"service {self.service_name}: bad request: {err}")
            return None
        address = (delivery.sender, delivery.endpoint, delivery.seq)
        return functools.partial(self._answer, request, address)

    def _answer(self, request: Any, address: tuple[int, int, int]) -> Any:
        """Run the callback and send its response (a coroutine callback: once it returns)."""
        try:
            response = self.callback(request, self.srv_type.Response())
        except Exception as err:
            self._fail(err, address)
            raise  # logged with the node's name by the executor; the server keeps serving
        if inspect.iscoroutine(response):
            return self._answer_later(response, address)
        self._respond(response, address)
        return None

    async def _answer_later(
        self, pending: Coroutine[Any, Any, Any], address: tuple[int, int, int]
    ) -> None:
        try:
            response = await pending
        except Exception as err:
            self._fail(err, address)
            raise
        self._respond(response, address)

    def _respond(self, response: Any, address: tuple[int, int, int]) -> None:
        try:
            if getattr(response, "__msgtype__", None) != self.srv_type.Response.__msgtype__:
                raise TypeError(
                    f"service {self.service_name} callback must return a "
                    f"{self.srv_type.Response.__msgtype__}, got {type(response).__name__}"
                )
            payload = self._store.serialize(response)
        except Exception as err:
            self._fail(err, address)
            raise
        self._writer.send(payload, address=address)
        self.handled += 1

    def _fail(self, err: Exception, address: tuple[int, int, int]) -> None:
        """Tell the caller at once that this request failed, so it need not wait it out."""
        with contextlib.suppress(RoslError):  # the callback's error is the one worth logging
            self._writer.send(failure_payload(err), kind=Kind.FAILURE, address=address)

    def record(self) -> EndpointRecord:
        """This server as discovery announces it."""
        return EndpointRecord(
            SERVER, self.service_name, self.type_name, self.endpoint, {}, {"handled": self.handled}
        )

    def close(self) -> None:
        """Stop serving."""
        self.destroyed = True
        self.node.participant.unlisten(self._topic, self)

    def destroy(self) -> None:
        """Stop serving (rclpy: node.destroy_service)."""
        self.node.destroy_service(self)
