"""rosidl_runtime_py.utilities: interfaces by full name (``rosl.idl.lookup``)."""

from rosl.idl.lookup import (
    get_action,
    get_action_namespaced_type,
    get_interface,
    get_message,
    get_message_namespaced_type,
    get_namespaced_type,
    get_service,
    get_service_namespaced_type,
    is_action,
    is_message,
    is_service,
)

__all__ = [
    "get_action",
    "get_action_namespaced_type",
    "get_interface",
    "get_message",
    "get_message_namespaced_type",
    "get_namespaced_type",
    "get_service",
    "get_service_namespaced_type",
    "is_action",
    "is_message",
    "is_service",
]
