"""Flat types' generated serializers: rosbags' bytes for every string length, errors named."""

from __future__ import annotations

import random
from typing import TYPE_CHECKING

import pytest

from rosl.idl import registry
from rosl.idl.errors import FieldError
from rosl.idl.flat_serde import flat_serializer
from tests.idl.test_messages import HUMBLE, SHIPPED_HUMBLE_TYPES, random_message, to_rosbags

if TYPE_CHECKING:
    from rosl.idl.messages import Message

FLAT_TYPES = [
    name for name in SHIPPED_HUMBLE_TYPES if flat_serializer(registry.get_message_class(name))
]


def _strings(message: Message) -> list[tuple[Message, str]]:
    """Every (message, attribute) holding a string, nested ones included."""
    found = []
    for attr, ftype in zip(message._fields, message._field_types, strict=True):
        if ftype.base == "string":
            found.append((message, attr))
        elif not ftype.is_primitive:
            found.extend(_strings(getattr(message, attr)))
    return found


def test_the_common_small_types_are_flat_and_types_with_arrays_or_bytes_are_not():
    for name in ("std_msgs/msg/String", "std_msgs/msg/Header", "geometry_msgs/msg/Twist",
                 "geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/TransformStamped",
                 "builtin_interfaces/msg/Time", "std_msgs/msg/Bool"):  # fmt: skip
        assert name in FLAT_TYPES
    for name in ("sensor_msgs/msg/LaserScan", "sensor_msgs/msg/Image", "std_msgs/msg/Byte",
                 "std_msgs/msg/Empty", "geometry_msgs/msg/PoseWithCovariance"):  # fmt: skip
        assert flat_serializer(registry.get_message_class(name)) is None


@pytest.mark.parametrize("type_name", FLAT_TYPES)
def test_bytes_equal_rosbags_for_every_string_length_modulo_8(type_name: str) -> None:
    rng = random.Random(type_name)
    message_cls = registry.get_message_class(type_name)
    serialize = flat_serializer(message_cls)
    assert serialize is not None
    store = registry.store()
    for length in range(17):  # every offset modulo 8 after each string, twice
        message = random_message(message_cls, rng)
        for owner, attr in _strings(message):
            setattr(owner, attr, "".join(rng.choice("aé€z") for _ in range(length)))
        ours = serialize(message)
        assert ours == bytes(HUMBLE.serialize_cdr(to_rosbags(message), type_name))
        assert store.deserialize(ours, type_name) == message
        assert store.serialize(message) == ours  # the store's way for the type


def test_a_wrong_value_in_a_flat_message_names_the_field_whichever_way_it_is_serialized():
    twist_cls = registry.get_message_class("geometry_msgs/msg/Twist")
    store = registry.store()
    twist = twist_cls()
    object.__setattr__(twist.angular, "z", "fast")  # past the setter's own check
    for serialize in (store.serialize, store.class_serializer(twist_cls)):
        with pytest.raises(FieldError, match=r"Twist\.angular\.z: expects a float64"):
            serialize(twist)


def test_a_string_field_holding_something_else_names_the_field():
    string_cls = registry.get_message_class("std_msgs/msg/String")
    message = string_cls()
    object.__setattr__(message, "data", 5)
    with pytest.raises(FieldError, match=r"String\.data"):
        registry.store().class_serializer(string_cls)(message)


KEYWORDS_MSG = """\
byte from
float64[] values
string class
geometry_msgs/Point global
"""


def test_fields_named_as_python_keywords_serialize_in_every_case(make_package) -> None:
    make_package("keywords_pkg", {"msg/Keywords.msg": KEYWORDS_MSG})
    keywords_cls = registry.get_message_class("keywords_pkg/msg/Keywords")
    store = registry.store()
    point = registry.get_message_class("geometry_msgs/msg/Point")(x=2.5)
    empty = keywords_cls(from_=b"\x07", class_="c", global_=point)  # values: none made yet
    full = keywords_cls(from_=b"\x07", class_="c", global_=point, values=[1.0, 2.0])
    for message in (empty, full):
        raw = store.serialize(message)
        assert raw[4:5] == b"\x07"
        assert store.deserialize(raw, "keywords_pkg/msg/Keywords") == message


def test_a_bounded_string_in_a_nested_message_is_checked_as_in_its_own(make_package) -> None:
    make_package(
        "bounds_pkg", {"msg/Inner.msg": "string<=3 name\n", "msg/Outer.msg": "Inner inner\n"}
    )
    outer = registry.get_message_class("bounds_pkg/msg/Outer")()
    outer.inner.name = "abc"
    registry.store().serialize(outer)
    outer.inner.name = "toolong"  # (assignment does not check; sending does, as rclpy's)
    for serialize in (registry.store().serialize, registry.store().serializer(outer.__msgtype__)):
        with pytest.raises(FieldError, match=r"Outer\.inner\.name: string longer than its bound 3"):
            serialize(outer)


@pytest.mark.parametrize(
    ("type_name", "value", "expected"),
    [
        ("std_msgs/msg/Int8", 1.0, r"Int8\.data: expects a whole number \(int8\), got float 1.0"),
        ("std_msgs/msg/Float32", 1e39, r"Float32\.data: float 1e\+39 is out of range for float32"),
        ("std_msgs/msg/Float64", 10**400, r"Float64\.data: int 1000.* is out of range for float64"),
        (
            "std_msgs/msg/String",
            "a\udc80",
            r"String\.data: not UTF-8 text \(surrogates not allowed\)",
        ),
    ],
)
def test_a_value_its_field_cannot_carry_is_one_error_naming_the_field(
    type_name: str, value: object, expected: str
) -> None:
    message = registry.get_message_class(type_name)()
    message.data = value
    store = registry.store()
    for serialize in (store.serialize, store.class_serializer(type(message))):
        with pytest.raises(FieldError, match=expected):
            serialize(message)


def test_float_fields_keep_infinities_and_nan() -> None:
    message = registry.get_message_class("std_msgs/msg/Float32")(data=float("inf"))
    assert registry.store().deserialize(
        registry.store().serialize(message), "std_msgs/msg/Float32"
    ).data == float("inf")
