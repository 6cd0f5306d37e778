"""rosidl_runtime_py.import_message (``rosl.idl.lookup``)."""

from rosl.idl.lookup import import_interface as import_message_from_namespaced_type

__all__ = ["import_message_from_namespaced_type"]
