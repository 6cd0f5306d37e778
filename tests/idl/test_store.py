"""The store's decoder for one type: what ``Store.deserialize`` gives, the same errors."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from rosl.idl import registry
from rosl.idl.errors import InterfaceError

TYPES = ("std_msgs/msg/String", "sensor_msgs/msg/LaserScan", "std_msgs/msg/Int32MultiArray")


def example(type_name: str) -> Any:
    cls = registry.get_message_class(type_name)
    if type_name == "std_msgs/msg/String":
        return cls(data="héllo")
    if type_name == "sensor_msgs/msg/LaserScan":
        return cls(ranges=[1.0, 2.5, 3.0], intensities=[0.5], angle_max=3.14)
    return cls(data=[1, -2, 3])


def outcome(decode: Any, data: Any) -> tuple[str, Any]:
    try:
        return "message", decode(data)
    except InterfaceError as err:
        return "error", str(err)


def payloads(type_name: str) -> list[bytes]:
    """A message's CDR, and ways of spoiling it."""
    store = registry.store()
    good = store.serialize(example(type_name))
    big_endian = bytes(
        store._typestore.serialize_cdr(example(type_name), type_name, little_endian=False)
    )
    return [
        good,
        good + b"\x00\x00\x00",  # padding rosbags allows
        good + b"\x00" * 8,  # more bytes than the message
        good[:-1],  # cut short
        good[:6],
        good[:3],
        b"",
        b"\x01\x01" + good[2:],  # not CDR
        big_endian,
    ]


@pytest.mark.parametrize("type_name", TYPES)
def test_the_decoder_gives_what_deserialize_gives(type_name: str) -> None:
    store = registry.store()
    spoiled = payloads(type_name)
    decode = store.decoder(type_name)
    for data in spoiled:
        for given in (memoryview(data), memoryview(bytearray(data)), bytearray(data), data):
            assert outcome(decode, given) == outcome(
                lambda d: store.deserialize(d, type_name), given
            ), (given, data)


def test_a_decoded_message_owns_its_arrays_and_they_are_writable() -> None:
    store = registry.store()
    data = bytearray(store.serialize(example("sensor_msgs/msg/LaserScan")))
    message = store.decoder("sensor_msgs/msg/LaserScan")(memoryview(bytes(data)))
    assert isinstance(message.ranges, np.ndarray)
    assert list(message.ranges) == [1.0, 2.5, 3.0]
    message.ranges[0] = 9.0  # writable, as in rclpy
    again = store.decoder("sensor_msgs/msg/LaserScan")(memoryview(bytes(data)))
    assert list(again.ranges) == [1.0, 2.5, 3.0]  # nothing shared with the first message


def test_the_decoder_reports_a_bad_message_as_deserialize_does() -> None:
    store = registry.store()
    registry.get_message_class("std_msgs/msg/String")
    with pytest.raises(InterfaceError, match=r"cannot decode std_msgs/msg/String \(3 bytes\)"):
        store.decoder("std_msgs/msg/String")(memoryview(b"\x00\x01\x00"))
