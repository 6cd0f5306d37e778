"""rosidl_runtime_py and rclpy.serialization under rosl, checked against upstream's tests."""

from __future__ import annotations

import array
from collections import OrderedDict

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

import rosl.compat

rosl.compat.install()


def test_message_to_yaml_ordereddict_and_csv_follow_field_order_and_truncation() -> None:
    from geometry_msgs.msg import Point
    from rosidl_runtime_py import message_to_csv, message_to_ordereddict, message_to_yaml
    from std_msgs.msg import Float64MultiArray, String

    assert message_to_yaml(Point(x=1.0, y=2.0, z=3.0)) == "x: 1.0\ny: 2.0\nz: 3.0\n"
    assert message_to_yaml(Point(x=1.0), flow_style=True) == "{x: 1.0, y: 0.0, z: 0.0}\n"
    ordered = message_to_ordereddict(String(data="hello world"), truncate_length=5)
    assert isinstance(ordered, OrderedDict)
    assert ordered == OrderedDict(data="hello...")
    values = Float64MultiArray(data=[1.5, 2.5, 3.5])
    assert message_to_csv(values, truncate_length=2).endswith(",1.5,2.5,...")
    assert "<sequence type: double, length: 3>" in message_to_yaml(values, no_arr=True)


def test_set_message_fields_sets_nested_fields_and_casts_as_upstream() -> None:
    from rosidl_runtime_py import set_message_fields
    from sensor_msgs.msg import PointCloud2
    from std_msgs.msg import Int32

    number = Int32()
    set_message_fields(number, {"data": "42"})  # rosidl_runtime_py casts with the field's type
    assert number.data == 42
    cloud = PointCloud2()
    set_message_fields(
        cloud,
        {"header": {"frame_id": "map"}, "fields": [{"name": "x", "datatype": 7, "count": 1}]},
    )
    assert cloud.header.frame_id == "map"
    assert cloud.fields[0].name == "x"
    assert cloud.fields[0].datatype == 7


def test_set_message_fields_raises_the_kinds_upstream_raises() -> None:
    from rosidl_runtime_py import set_message_fields
    from std_msgs.msg import Header, Int32

    with pytest.raises(AttributeError, match="has no field 'dta'"):
        set_message_fields(Int32(), {"dta": 1})
    with pytest.raises(ValueError, match="data"):
        set_message_fields(Int32(), {"data": "this is not an integer"})
    with pytest.raises(ValueError, match="out of range"):
        set_message_fields(Int32(), {"data": 2**40})
    with pytest.raises(
        TypeError, match=r"^Value 'auto' is expected to be a dictionary but is a str$"
    ):
        set_message_fields(Header(), {"stamp": "auto"})


def test_set_message_fields_expands_header_auto_and_time_now_into_setters() -> None:
    from builtin_interfaces.msg import Time
    from geometry_msgs.msg import PoseStamped
    from rosidl_runtime_py import set_message_fields

    pose = PoseStamped()
    setters = set_message_fields(
        pose, {"header": "auto"}, expand_header_auto=True, expand_time_now=True
    )
    assert len(setters) == 1
    setters[0](Time(sec=1, nanosec=2))
    assert (pose.header.stamp.sec, pose.header.stamp.nanosec) == (1, 2)
    stamped = PoseStamped()
    setters = set_message_fields(
        stamped, {"header": {"stamp": "now", "frame_id": "odom"}}, expand_time_now=True
    )
    setters[0](Time(sec=5))
    assert stamped.header.stamp.sec == 5
    assert stamped.header.frame_id == "odom"


def test_utilities_find_interfaces_by_full_name_and_fail_as_upstream() -> None:
    from rosidl_runtime_py.utilities import get_interface, get_message, get_service
    from std_msgs.msg import String
    from std_srvs.srv import SetBool

    assert get_message("std_msgs/msg/String") is String
    assert get_message("std_msgs/String") is String
    assert get_interface("std_srvs/srv/SetBool") is SetBool
    assert get_service("std_srvs/SetBool") is SetBool
    with pytest.raises(ValueError, match="Expected the full name of a message"):
        get_message("std_srvs/srv/SetBool")
    with pytest.raises(AttributeError, match="has no attribute 'Strin'"):
        get_message("std_msgs/msg/Strin")
    with pytest.raises(ModuleNotFoundError):
        get_message("no_such_pkg/msg/Thing")


def test_get_action_of_an_unknown_action_raises_as_importing_it_would() -> None:
    from rosidl_runtime_py.utilities import get_action

    with pytest.raises(ModuleNotFoundError):
        get_action("std_msgs/action/Nothing")


def test_get_interfaces_lists_each_kind_and_unknown_packages_are_lookup_errors() -> None:
    from rosidl_runtime_py import (
        get_interface_packages,
        get_interface_path,
        get_message_interfaces,
        get_service_interfaces,
    )

    assert "std_msgs" in get_interface_packages()
    assert "msg/String" in get_message_interfaces(["std_msgs"])["std_msgs"]
    assert get_service_interfaces(["std_msgs"]) == {}
    assert "srv/SetBool" in get_service_interfaces(["std_srvs"])["std_srvs"]
    assert get_interface_path("std_msgs/msg/String").endswith("std_msgs/msg/String.msg")
    with pytest.raises(LookupError, match="Unknown package 'nope'"):
        get_message_interfaces(["nope"])
    with pytest.raises(ValueError, match="at least two parts"):
        get_interface_path("std_msgs")


def test_serialize_message_is_byte_equal_to_rosbags_and_round_trips() -> None:
    from rclpy.serialization import deserialize_message, serialize_message
    from sensor_msgs.msg import Image

    image = Image(height=2, width=3, encoding="mono8", step=3)
    image.data = np.arange(6, dtype=np.uint8)
    data = serialize_message(image)
    assert isinstance(data, bytes)
    theirs = get_typestore(Stores.ROS2_HUMBLE)
    reference = theirs.types["sensor_msgs/msg/Image"](
        header=theirs.types["std_msgs/msg/Header"](
            stamp=theirs.types["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id=""
        ),
        height=2, width=3, encoding="mono8", is_bigendian=0, step=3,
        data=np.arange(6, dtype=np.uint8),
    )  # fmt: skip
    assert data == bytes(theirs.serialize_cdr(reference, "sensor_msgs/msg/Image"))
    back = deserialize_message(data, Image)
    assert back == image


def test_deserialize_message_with_a_service_type_is_an_error_naming_it() -> None:
    from rclpy.serialization import deserialize_message, serialize_message
    from std_srvs.srv import SetBool

    with pytest.raises(TypeError, match="this might be a service or action"):
        deserialize_message(b"\x00\x01\x00\x00", SetBool)
    with pytest.raises(TypeError, match="expects a message"):
        serialize_message("not a message")


def test_received_arrays_are_writable_copies_not_views_of_the_bytes() -> None:
    from rclpy.serialization import deserialize_message, serialize_message
    from sensor_msgs.msg import Image

    data = serialize_message(Image(data=b"\x01\x02\x03"))
    first = deserialize_message(data, Image)
    first.data[0] = 9  # as with rclpy's array.array: a received message may be changed
    second = deserialize_message(data, Image)
    assert second.data.tolist() == [1, 2, 3]


def test_large_arrays_are_set_from_bytes_numpy_and_array_array_alike() -> None:
    from sensor_msgs.msg import Image

    raw = bytes(range(256)) * 4096
    sources = [
        raw,
        bytearray(raw),
        memoryview(raw),
        np.frombuffer(raw, np.uint8),
        array.array("B", raw),
    ]
    for source in sources:
        image = Image(data=source)
        assert image.data.dtype == np.uint8
        assert image.data.tobytes() == raw, type(source)


def _filled() -> list[object]:
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
    from nav_msgs.msg import Odometry
    from rcl_interfaces.msg import ParameterValue
    from sensor_msgs.msg import CameraInfo, JointState
    from std_msgs.msg import Header, UInt8MultiArray

    odometry = Odometry(child_frame_id="base")
    odometry.pose.covariance = np.arange(36, dtype=np.float64)
    odometry.twist.twist.linear.x = 0.5
    return [
        JointState(header=Header(frame_id="j"), name=["a", "b"], position=[1.0, 2.0], effort=[3.0]),
        odometry,
        CameraInfo(width=640, d=[0.1, 0.2], k=np.eye(3).ravel(), distortion_model="plumb_bob"),
        UInt8MultiArray(data=bytes(range(256))),
        ParameterValue(type=5, byte_array_value=[b"\x01", b"\xff"]),
        DiagnosticArray(
            status=[DiagnosticStatus(level=b"\x02", name="n", values=[KeyValue(key="k")])]
        ),
    ]


@pytest.mark.parametrize("index", range(6))
def test_serialization_round_trips_and_rosbags_reads_the_same_bytes(index: int) -> None:
    from rclpy.serialization import deserialize_message, serialize_message

    message = _filled()[index]
    data = serialize_message(message)
    assert deserialize_message(data, type(message)) == message
    theirs = get_typestore(Stores.ROS2_HUMBLE)
    type_name = message.__msgtype__
    assert bytes(theirs.serialize_cdr(theirs.deserialize_cdr(data, type_name), type_name)) == data


def test_float32_values_come_back_rounded_to_float32() -> None:
    from geometry_msgs.msg import Point32
    from rclpy.serialization import deserialize_message, serialize_message

    exact = deserialize_message(serialize_message(Point32(x=1.125)), Point32)
    assert exact.x == 1.125
    rounded = deserialize_message(serialize_message(Point32(x=3.14)), Point32)
    assert round(rounded.x, 2) == 3.14


def test_message_to_ordereddict_nests_ordered_dicts_for_nested_messages() -> None:
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
    from rosidl_runtime_py import message_to_ordereddict

    data = message_to_ordereddict(DiagnosticArray(status=[DiagnosticStatus(name="motor")]))
    assert isinstance(data["header"], OrderedDict)
    assert isinstance(data["status"][0], OrderedDict)
    assert list(data["status"][0])[:2] == ["level", "name"]
    assert data["status"][0]["name"] == "motor"
