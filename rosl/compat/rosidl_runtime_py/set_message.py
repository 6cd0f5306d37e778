"""rosidl_runtime_py.set_message: ``set_message_fields`` (``rosl.idl.assign``)."""

from rosl.idl.assign import set_message_fields

__all__ = ["set_message_fields"]
