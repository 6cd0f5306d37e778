"""``import rosidl_runtime_py`` under rosl: message conversion, field setting, interface lookup.

Backed by ``rosl.idl`` (``yaml_io``, ``assign``, ``lookup``); no logic here.
"""

from rosl.idl.assign import set_message_fields
from rosl.idl.lookup import (
    get_action_interfaces,
    get_interface_packages,
    get_interface_path,
    get_interfaces,
    get_message_interfaces,
    get_service_interfaces,
)
from rosl.idl.lookup import import_interface as import_message_from_namespaced_type
from rosl.idl.yaml_io import message_slot_types as get_message_slot_types
from rosl.idl.yaml_io import message_to_csv, message_to_ordereddict, message_to_yaml

__all__ = [
    "get_action_interfaces",
    "get_interface_packages",
    "get_interface_path",
    "get_interfaces",
    "get_message_interfaces",
    "get_message_slot_types",
    "get_service_interfaces",
    "import_message_from_namespaced_type",
    "message_to_csv",
    "message_to_ordereddict",
    "message_to_yaml",
    "set_message_fields",
]
