"""example_interfaces' messages: one ``data`` field each, as std_msgs' messages of the same name.

ros2/example_interfaces defines Bool, Byte, Char, Empty, Float32/64, Int8..64, UInt8..64 and
String with the fields of std_msgs' (rosbags, the reference of test_shipped_interfaces.py,
has no example_interfaces); ros2/demos' lifecycle_py talker publishes example_interfaces'
String. WString is left out: rosl has no wstring.
"""

from __future__ import annotations

import pytest
from rosbags.typesys import Stores, get_typestore

from rosl.idl import registry
from rosl.idl.store import typesdict_entry
from rosl.resources import shipped_dir

HUMBLE = get_typestore(Stores.ROS2_HUMBLE)
NAMES = [
    "Bool", "Byte", "Char", "Empty", "Float32", "Float64", "Int8", "Int16", "Int32", "Int64",
    "String", "UInt8", "UInt16", "UInt32", "UInt64",
]  # fmt: skip


def test_the_shipped_messages_are_example_interfaces_scalar_ones():
    folder = shipped_dir("interfaces") / "example_interfaces" / "msg"
    assert sorted(p.stem for p in folder.glob("*.msg")) == sorted(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_each_has_the_fields_of_the_std_msgs_message_of_its_name(name):
    spec = registry.resolve(registry.load_spec(f"example_interfaces/msg/{name}"))
    constants, fields = typesdict_entry(spec)
    ref_constants, ref_fields = HUMBLE.fielddefs[f"std_msgs/msg/{name}"]

    assert [tuple(c) for c in constants] == [tuple(c) for c in ref_constants] == []
    assert [(n, d) for n, d in fields] == [(n, d) for n, d in ref_fields]


def test_a_string_round_trips_under_its_own_type_name():
    string = registry.get_message_class("example_interfaces/msg/String")
    registry.get_message_class("std_msgs/msg/String")
    store = registry.store()
    data = store.serialize(string(data="Lifecycle HelloWorld #1"))

    assert store.deserialize(data, "example_interfaces/msg/String") == string(
        data="Lifecycle HelloWorld #1"
    )
    assert store.type_hash("example_interfaces/msg/String") != store.type_hash(
        "std_msgs/msg/String"
    )
