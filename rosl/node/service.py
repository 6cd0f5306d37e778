"""Service servers: requests in, the callback's response out, addressed to the caller."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.bus.header import Kind, topic_hash, type_hash
from rosl.bus.wire import Writer
from rosl.graph.records import SERVER, EndpointRecord
from rosl.idl import registry
from rosl.idl.errors import InterfaceError

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.wire import Delivery
    from rosl.idl.messages import ServiceType
    from rosl.node.node import Node


class Service:
    """Serves one service name (rclpy.service.Service)."""

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
        participant.listen(self._topic, self)

    def deliver(self, delivery: Delivery) -> None:
        """Answer one request."""
        if delivery.kind != Kind.REQUEST or self.destroyed:
            return
        if delivery.type != self._type:
            self.node.get_logger().warn(
                f"service {self.service_name} ({self.type_name}) got a request of another "
                "type; ignored",
                once=True,
            )
            return
        try:
            request = self._store.deserialize(delivery.payload, self.srv_type.Request.__msgtype__)
        except InterfaceError as err:
            self.node.get_logger().warn(f"service {self.service_name}: bad request: {err}")
            return
        address = (delivery.sender, delivery.endpoint, delivery.seq)
        self.node.run_callback(lambda: self._answer(request, address), self.service_name)

    def _answer(self, request: Any, address: tuple[int, int, int]) -> None:
        response = self.callback(request, self.srv_type.Response())
        if getattr(response, "__msgtype__", None) != self.srv_type.Response.__msgtype__:
            raise TypeError(
                f"service {self.service_name} callback must return a "
                f"{self.srv_type.Response.__msgtype__}, got {type(response).__name__}"
            )
        self._writer.send(self._store.serialize(response), address=address)
        self.handled += 1

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
