"""Service traffic as ROS 2 (Jazzy) service introspection events.

Requests and responses cross the bus as datagrams every process can see, so an observer (a
recorder, ``service echo``) turns them into ``<Service>_Event`` messages: a request datagram
is a ``REQUEST_SENT`` event, a response datagram a ``RESPONSE_SENT`` event, with the client's
GID and the request's sequence number in ``service_msgs/ServiceEventInfo``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.bus.header import Kind
from rosl.idl import registry

if TYPE_CHECKING:
    from rosl.bus.wire import Delivery

REQUEST_SENT = 0
REQUEST_RECEIVED = 1
RESPONSE_SENT = 2
RESPONSE_RECEIVED = 3
EVENT_NAMES = {0: "REQUEST_SENT", 1: "REQUEST_RECEIVED", 2: "RESPONSE_SENT", 3: "RESPONSE_RECEIVED"}


def event_type_name(service_type: str) -> str:
    """``pkg/srv/Name`` → ``pkg/srv/Name_Event``."""
    return f"{service_type}_Event"


def event_topic(service_name: str) -> str:
    """Where ROS 2 publishes a service's events: ``<service>/_service_event``."""
    return f"{service_name.rstrip('/')}/_service_event"


def client_gid(process: int, endpoint: int) -> list[int]:
    """The 16 GID bytes of a client endpoint (as ``char[16]`` values)."""
    return list(process.to_bytes(8, "little") + endpoint.to_bytes(2, "little") + bytes(6))


def event_from_delivery(delivery: Delivery, service_type: str) -> Any | None:
    """Build the ``<Service>_Event`` for a request or response datagram (None for others)."""
    event_cls = registry.get_message_class(event_type_name(service_type))
    store = registry.store()
    info_cls = registry.get_message_class("service_msgs/msg/ServiceEventInfo")
    stamp = registry.get_message_class("builtin_interfaces/msg/Time")(
        sec=delivery.stamp // 1_000_000_000, nanosec=delivery.stamp % 1_000_000_000
    )
    if delivery.kind == Kind.REQUEST:
        request = store.deserialize(delivery.payload, f"{service_type}_Request")
        info = info_cls(
            event_type=REQUEST_SENT, stamp=stamp,
            client_gid=client_gid(delivery.sender, delivery.endpoint), sequence_number=delivery.seq,
        )  # fmt: skip
        return event_cls(info=info, request=[request], response=[])
    if delivery.kind == Kind.RESPONSE and delivery.address is not None:
        process, endpoint, correlation = delivery.address
        response = store.deserialize(delivery.payload, f"{service_type}_Response")
        info = info_cls(
            event_type=RESPONSE_SENT, stamp=stamp, client_gid=client_gid(process, endpoint),
            sequence_number=correlation,
        )  # fmt: skip
        return event_cls(info=info, request=[], response=[response])
    return None
