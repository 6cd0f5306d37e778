"""rosidl_runtime_py.convert: messages as YAML, CSV and ordered dicts (``rosl.idl.yaml_io``)."""

from rosl.idl.yaml_io import message_slot_types as get_message_slot_types
from rosl.idl.yaml_io import message_to_csv, message_to_ordereddict, message_to_yaml

__all__ = ["get_message_slot_types", "message_to_csv", "message_to_ordereddict", "message_to_yaml"]
