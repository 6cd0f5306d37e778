"""rclpy.serialization: messages to and from CDR bytes (``rosl.idl.cdr``)."""

from rosl.idl.cdr import deserialize_message, serialize_message

__all__ = ["deserialize_message", "serialize_message"]
