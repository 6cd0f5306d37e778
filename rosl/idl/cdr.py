"""Messages to and from CDR bytes by value: what ``rclpy.serialization`` offers.

The bytes are exactly what travels on the wire and what a recording holds (the 4-byte
encapsulation header, then little-endian CDR), byte for byte what rosbags writes.
"""

from __future__ import annotations

from typing import Any

from rosl.idl import registry
from rosl.idl.base import Message
from rosl.idl.errors import NotAMessageError

__all__ = ["deserialize_message", "serialize_message"]


def serialize_message(message: Any) -> bytes:
    """Return the CDR bytes of ``message``.

    Raises:
        NotAMessageError: ``message`` is not a message.
        FieldError: a field holds a value its type cannot carry.
    """
    if not isinstance(message, Message):
        raise NotAMessageError(f"serialize_message expects a message, got {_name(message)}")
    return registry.store().serialize(message)


def deserialize_message(
    serialized_message: bytes | bytearray | memoryview, message_type: Any
) -> Any:
    """Return a message of ``message_type`` decoded from CDR bytes.

    Raises:
        NotAMessageError: ``message_type`` is not a message class (a service, say).
        InterfaceError: the bytes are not a ``message_type``.
    """
    if not (isinstance(message_type, type) and issubclass(message_type, Message)):
        raise NotAMessageError(
            f"The message type provided is not valid ({_name(message_type)}), "
            "this might be a service or action"
        )
    return registry.store().deserialize(serialized_message, message_type.__msgtype__)


def _name(value: Any) -> str:
    if isinstance(value, type):
        return getattr(value, "__srvtype__", None) or value.__name__
    return type(value).__name__
