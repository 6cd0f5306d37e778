"""Message classes: construction, equality, repr, dicts, and CDR identical to rosbags."""

from __future__ import annotations

import random

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from rosl.idl import registry
from rosl.idl.errors import FieldError
from rosl.idl.messages import Message, from_dict, to_dict
from rosl.idl.parser import FLOATS, INTEGER_RANGES, ArrayKind

HUMBLE = get_typestore(Stores.ROS2_HUMBLE)
SHIPPED_HUMBLE_TYPES = sorted(
    name
    for name in HUMBLE.fielddefs
    if name.split("/")[0] not in ("rmw_dds_common", "rosbag2_interfaces")
)


def cls(name: str) -> type[Message]:
    return registry.get_message_class(name)


def test_twist_default_constructs_with_nested_defaults():
    twist = cls("geometry_msgs/msg/Twist")()
    assert (twist.linear.x, twist.linear.y, twist.angular.z) == (0.0, 0.0, 0.0)
    assert twist.linear is not twist.angular


def test_keyword_construction_and_attribute_assignment():
    vector = cls("geometry_msgs/msg/Vector3")
    twist = cls("geometry_msgs/msg/Twist")(linear=vector(x=0.2))
    twist.angular.z = 0.5
    assert twist.linear.x == 0.2
    assert twist.angular.z == 0.5


def test_positional_construction_follows_field_order():
    vector = cls("geometry_msgs/msg/Vector3")(1.0, 2.0, 3.0)
    assert (vector.x, vector.y, vector.z) == (1.0, 2.0, 3.0)


def test_equality_compares_all_fields_including_arrays():
    scan = cls("sensor_msgs/msg/LaserScan")
    assert scan(ranges=[1.0, 2.0]) == scan(ranges=np.array([1.0, 2.0], dtype=np.float32))
    assert scan(ranges=[1.0, 2.0]) != scan(ranges=[1.0, 2.5])
    assert cls("geometry_msgs/msg/Point")() != cls("geometry_msgs/msg/Vector3")()


def test_repr_matches_rclpy_style():
    twist = cls("geometry_msgs/msg/Twist")()
    twist.linear.x = 0.2
    assert repr(twist) == (
        "geometry_msgs.msg.Twist(linear=geometry_msgs.msg.Vector3(x=0.2, y=0.0, z=0.0), "
        "angular=geometry_msgs.msg.Vector3(x=0.0, y=0.0, z=0.0))"
    )
    request = registry.get_service_class("std_srvs/srv/SetBool").Request(data=True)
    assert repr(request) == "std_srvs.srv.SetBool_Request(data=True)"


def test_repr_shows_sequences_as_lists_and_fixed_arrays_as_numpy():
    scan = cls("sensor_msgs/msg/LaserScan")(ranges=[1.5])
    assert "ranges=[1.5]" in repr(scan)
    odom = cls("nav_msgs/msg/Odometry")()
    assert "covariance=array([0., 0.," in repr(odom)


def test_default_values_and_constants_are_class_attributes():
    quaternion = cls("geometry_msgs/msg/Quaternion")
    assert quaternion().w == 1.0
    assert quaternion.W__DEFAULT == 1.0
    status = cls("sensor_msgs/msg/NavSatStatus")
    assert status.STATUS_FIX == 0
    assert status.SERVICE_GALILEO == 8


def test_numeric_arrays_accept_lists_tuples_bytes_and_numpy():
    image = cls("sensor_msgs/msg/Image")
    assert image(data=b"\x01\x02").data.tolist() == [1, 2]
    assert image(data=[1, 2]).data.dtype == np.uint8
    scan = cls("sensor_msgs/msg/LaserScan")(ranges=(1, 2))
    assert scan.ranges.dtype == np.float32
    array = np.arange(3, dtype=np.float32)
    scan.ranges = array
    assert np.shares_memory(scan.ranges, array)  # held without a copy (a view that can grow)


def test_fixed_arrays_check_their_length_on_assignment():
    odom = cls("nav_msgs/msg/Odometry")()
    with pytest.raises(FieldError, match="needs exactly 36 values, got 2"):
        odom.pose.covariance = [1.0, 2.0]


def test_integer_arrays_reject_out_of_range_and_fractional_values():
    image = cls("sensor_msgs/msg/Image")
    with pytest.raises(FieldError, match="0 to 255"):
        image(data=[256])
    with pytest.raises(FieldError, match="expects a list of uint8"):
        image(data=[1.5])


def test_unknown_keyword_names_the_field_and_suggests():
    with pytest.raises(FieldError, match="has no field 'linaer' \\(did you mean 'linear'\\?\\)"):
        cls("geometry_msgs/msg/Twist")(linaer=1)


def test_serializing_a_wrong_value_names_the_field_path():
    twist = cls("geometry_msgs/msg/Twist")()
    twist.linear.x = "fast"
    with pytest.raises(FieldError, match=r"geometry_msgs/msg/Twist\.linear\.x: expects a float64"):
        registry.store().serialize(twist)


def test_serializing_checks_string_bounds():
    message = cls("sensor_msgs/msg/NavSatFix")()
    message.header.frame_id = "ok"
    registry.store().serialize(message)  # unbounded: fine
    registry.clear()


def test_dict_round_trip_keeps_values():
    odom = cls("nav_msgs/msg/Odometry")()
    odom.header.frame_id = "odom"
    odom.pose.pose.position.x = 1.5
    data = to_dict(odom)
    assert data["header"]["frame_id"] == "odom"
    assert isinstance(data["pose"]["covariance"], list)
    assert from_dict(type(odom), data) == odom


def test_from_dict_reports_unknown_fields_and_wrong_types_by_path():
    twist = cls("geometry_msgs/msg/Twist")
    with pytest.raises(FieldError, match="has no field 'lineer'"):
        from_dict(twist, {"lineer": {}})
    with pytest.raises(FieldError, match=r"linear\.x: expects a float64 number, got str"):
        from_dict(twist, {"linear": {"x": "fast"}})
    with pytest.raises(FieldError, match=r"linear: expects a mapping"):
        from_dict(twist, {"linear": 3})


def test_from_dict_converts_ints_to_floats_and_numbers_to_strings():
    twist = from_dict(cls("geometry_msgs/msg/Twist"), {"linear": {"x": 1}})
    assert twist.linear.x == 1.0
    assert isinstance(twist.linear.x, float)
    string = from_dict(cls("std_msgs/msg/String"), {"data": 5})
    assert string.data == "5"


# --- CDR: byte-identical to rosbags for every shipped Humble type ------------------------------


def random_message(message_cls: type[Message], rng: random.Random, depth: int = 0) -> Message:
    values = {}
    for name, ftype in zip(message_cls._fields, message_cls._field_types, strict=True):
        if ftype.array is ArrayKind.FIXED:
            count = ftype.size
        elif ftype.array is ArrayKind.BOUNDED:
            count = rng.randint(0, ftype.size)
        else:
            count = rng.randint(0, 3 if depth < 2 else 0)
        if ftype.is_array:
            values[name] = [
                random_value(message_cls, name, ftype, rng, depth) for _ in range(count)
            ]
        else:
            values[name] = random_value(message_cls, name, ftype, rng, depth)
    return message_cls(**values)


def random_value(message_cls, name, ftype, rng, depth):
    base = ftype.base
    if not ftype.is_primitive:
        return random_message(message_cls._field_classes[name], rng, depth + 1)
    if base == "bool":
        return rng.random() < 0.5
    if base == "string":
        limit = ftype.string_bound or 6
        return "".join(rng.choice("abcxyz _#é") for _ in range(rng.randint(0, limit)))
    if base in FLOATS:
        value = rng.uniform(-1e3, 1e3)
        return float(np.float32(value)) if base == "float32" else value
    low, high = INTEGER_RANGES[base]
    if base == "byte":  # rclpy's bytes of length 1
        return bytes([rng.randint(0, 255)])
    return rng.randint(low, high)


def to_rosbags(message: Message):
    kwargs = {}
    for name, ftype in zip(message._fields, message._field_types, strict=True):
        value = getattr(message, name)
        if isinstance(value, Message):
            value = to_rosbags(value)
        elif isinstance(value, list) and not ftype.is_primitive:
            value = [to_rosbags(v) for v in value]
        elif ftype.base == "byte" and ftype.is_array:  # rosbags: an int8 array
            value = np.frombuffer(b"".join(value), dtype=np.int8)
        elif ftype.base == "byte":  # rosbags: a signed int
            value = int.from_bytes(value, "little", signed=True)
        kwargs[name] = value
    return HUMBLE.types[message.__msgtype__](**kwargs)


@pytest.mark.parametrize("type_name", SHIPPED_HUMBLE_TYPES)
def test_cdr_is_byte_identical_to_rosbags_and_round_trips(type_name):
    rng = random.Random(type_name)
    message_cls = cls(type_name)
    store = registry.store()
    for _ in range(3):
        message = random_message(message_cls, rng)
        ours = store.serialize(message)
        theirs = bytes(HUMBLE.serialize_cdr(to_rosbags(message), type_name))
        assert ours == theirs
        assert store.deserialize(ours, type_name) == message


# --- byte and bounded sequences as rclpy has them -----------------------------------------------

BYTES_MSG = """\
byte K=200
byte b 255
byte[3] fixed [0, 1, 255]
byte[] seq
byte[<=2] bounded
char c 65
uint8 u
string[<=3] names
string[2] pair
"""


@pytest.fixture
def bytes_cls(make_package) -> type[Message]:
    make_package("bytes_pkg", {"msg/Bytes.msg": BYTES_MSG})
    return cls("bytes_pkg/msg/Bytes")


def test_byte_fields_hold_bytes_of_length_one_and_char_an_int_as_rclpy_does(bytes_cls):
    message = bytes_cls()

    assert message.b == b"\xff"
    assert message.fixed == [b"\x00", b"\x01", b"\xff"]
    assert (message.seq, message.bounded) == ([], [])
    assert (message.c, message.u) == (65, 0)
    assert bytes_cls.K == b"\xc8"
    assert bytes_cls.FIXED__DEFAULT == [b"\x00", b"\x01", b"\xff"]
    assert cls("std_msgs/msg/Byte")().data == b"\x00"
    assert "b=b'\\xff', fixed=[b'\\x00', b'\\x01', b'\\xff'], seq=[]" in repr(message)


def test_byte_fields_take_bytes_and_numbers_up_to_255_and_refuse_the_rest(bytes_cls):
    message = bytes_cls(b=7, seq=b"\x00\xfe", bounded=[1, b"\x02"])
    assert message.b == b"\x07"
    assert (message.seq, message.bounded) == ([b"\x00", b"\xfe"], [b"\x01", b"\x02"])
    message.fixed = bytearray(b"abc")
    assert message.fixed == [b"a", b"b", b"c"]
    with pytest.raises(FieldError, match=r"Bytes field 'b': expects a byte .*got int 256"):
        message.b = 256
    with pytest.raises(FieldError, match=r"field 'b': expects a byte .*got bytes b'ab'"):
        message.b = b"ab"
    with pytest.raises(FieldError, match=r"field 'fixed': needs exactly 3 values, got 2"):
        message.fixed = [1, 2]
    with pytest.raises(FieldError, match=r"field 'bounded': holds at most 2 values, got 3"):
        message.bounded = b"xyz"


def test_bounded_sequences_of_strings_start_empty_and_fixed_arrays_filled(bytes_cls):
    message = bytes_cls()
    assert message.names == []
    assert message.pair == ["", ""]
    assert cls("std_msgs/msg/MultiArrayLayout")().dim == []


def test_byte_fields_go_on_the_wire_as_ros_writes_them_and_come_back_as_bytes(bytes_cls):
    store = registry.store()
    message = bytes_cls(seq=[0x7F, 0x80], bounded=[b"\x10"])
    raw = store.serialize(message)

    assert raw[4:8] == b"\xff\x00\x01\xff"  # b, then fixed
    assert raw[8:16] == b"\x02\x00\x00\x00\x7f\x80\x00\x00"  # seq: its length, then the bytes
    back = store.deserialize(raw, "bytes_pkg/msg/Bytes")
    assert back == message
    assert back.b == b"\xff"
    assert back.seq == [b"\x7f", b"\x80"]


def test_a_byte_array_item_set_by_hand_that_is_no_byte_is_named_on_serializing(bytes_cls):
    message = bytes_cls()
    message.seq.append("too long")
    with pytest.raises(FieldError, match=r"bytes_pkg/msg/Bytes\.seq\[0\]: expects a byte"):
        registry.store().serialize(message)


def test_byte_fields_from_yaml_values_and_to_ros2_yaml_and_csv(bytes_cls):
    from rosl.idl.yaml_io import message_to_csv, message_to_yaml, parse_yaml_mapping

    data = parse_yaml_mapping(
        "{b: 65, seq: [0, 255], bounded: !!binary AQI=, fixed: ['a', 'b', 'c']}"
    )
    message = from_dict(bytes_cls, data)

    assert message.b == b"A"
    assert message.seq == [b"\x00", b"\xff"]
    assert message.bounded == [b"\x01", b"\x02"]
    assert message.fixed == [b"a", b"b", b"c"]
    text = message_to_yaml(message)
    assert text.startswith('b: A\nfixed:\n- a\n- b\n- c\nseq:\n- "\\0"\n- ÿ\nbounded:\n- "\\x01"\n')
    assert message_to_csv(message).startswith("b'A',b'a',b'b',b'c',b'\\x00',b'\\xff',b'\\x01'")
    with pytest.raises(FieldError, match=r"^b: expects a byte .*got str 'AB'"):
        from_dict(bytes_cls, {"b": "AB"})
