"""numpy is loaded by the first numeric array, not by building or filling other messages."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from rosl.idl.registry import get_message_class

NO_ARRAYS = """
import sys
import rosl
from std_msgs.msg import Header, String
from rosl.idl.registry import get_message_class
from rosl.idl.yaml_io import message_to_yaml

get_message_class("rcl_interfaces/msg/ParameterValue")  # has numeric arrays: class only
header = Header(frame_id="map")
header.stamp.sec = 7
text = message_to_yaml(header) + message_to_yaml(String(data="hi"))
assert "sec: 7" in text and "data: hi" in text, text
print("numpy" in sys.modules)
"""


def test_messages_without_numeric_arrays_do_not_load_numpy() -> None:
    out = subprocess.run(
        [sys.executable, "-c", NO_ARRAYS], capture_output=True, text=True, timeout=60, check=True
    )
    assert out.stdout.strip() == "False", out.stdout + out.stderr


def test_numpy_values_are_still_taken_and_arrays_are_numpy() -> None:
    header = get_message_class("std_msgs/msg/Header")()
    header.stamp.sec = np.int32(3)
    assert header.stamp.sec == 3
    value = get_message_class("rcl_interfaces/msg/ParameterValue")(integer_array_value=[1, 2])
    assert isinstance(value.integer_array_value, np.ndarray)
    assert value.integer_array_value.dtype == np.int64
    assert value.integer_array_value.tolist() == [1, 2]
    value.byte_array_value = np.array([1, 255], dtype=np.int64)
    assert value.byte_array_value == [b"\x01", b"\xff"]


EMPTY_ARRAYS = """
import sys
from rosl.idl.cdr import serialize_message
from rosl.idl.registry import get_message_class

Event = get_message_class("rcl_interfaces/msg/ParameterEvent")
Parameter = get_message_class("rcl_interfaces/msg/Parameter")
Value = get_message_class("rcl_interfaces/msg/ParameterValue")
event = Event(node="/n", new_parameters=[Parameter(name="use_sim_time", value=Value(type=1))])
print(serialize_message(event).hex())
print("numpy" in sys.modules)
"""


def test_empty_numeric_arrays_are_serialized_without_loading_numpy() -> None:
    out = subprocess.run(
        [sys.executable, "-c", EMPTY_ARRAYS],
        capture_output=True, text=True, timeout=60, check=True,
    )  # fmt: skip
    data, loaded = out.stdout.split()
    assert loaded == "False", out.stdout + out.stderr
    # the same bytes as from a message whose empty arrays are numpy arrays (numpy loaded here)
    from rosl.idl.cdr import deserialize_message, serialize_message

    event_cls = get_message_class("rcl_interfaces/msg/ParameterEvent")
    parameter_cls = get_message_class("rcl_interfaces/msg/Parameter")
    value_cls = get_message_class("rcl_interfaces/msg/ParameterValue")
    value = value_cls(type=1, integer_array_value=np.zeros(0, np.int64), bool_array_value=[])
    event = event_cls(node="/n", new_parameters=[parameter_cls(name="use_sim_time", value=value)])
    assert isinstance(value.integer_array_value, np.ndarray)
    assert serialize_message(event).hex() == data
    back = deserialize_message(bytes.fromhex(data), event_cls)
    assert back == event
    assert back.new_parameters[0].value.double_array_value.tolist() == []


def test_an_empty_array_read_after_construction_is_a_growable_numpy_array() -> None:
    import copy

    value = get_message_class("rcl_interfaces/msg/ParameterValue")()
    twin = copy.deepcopy(value)
    assert twin == value
    array = value.integer_array_value
    assert isinstance(array, np.ndarray)
    assert array.dtype == np.int64
    assert array.tolist() == []
    array.append(5)
    assert value.integer_array_value.tolist() == [5]
    assert twin.integer_array_value.tolist() == []  # the copy has its own (still empty) field
    assert twin != value
    value.integer_array_value = None  # as at construction: empty again
    assert value.integer_array_value.tolist() == []


NODE_WITHOUT_NUMPY = """
import sys
import rosl
from std_msgs.msg import String

rosl.init([])
node = rosl.Node("lazy_numpy_probe")
node.declare_parameter("gain", 2.5)
heard = []
node.create_subscription(String, "/lazy_numpy_chatter", heard.append, 10)
publisher = node.create_publisher(String, "/lazy_numpy_chatter", 10)
for _ in range(200):
    publisher.publish(String(data="hi"))
    rosl.spin_once(node, timeout_sec=0.05)
    if heard:
        break
rosl.shutdown()
print(heard[0].data if heard else "nothing", "numpy" in sys.modules)
"""


def test_a_node_with_parameters_that_talks_and_listens_does_not_load_numpy(
    domain_id: int,
) -> None:
    out = subprocess.run(
        [sys.executable, "-c", NODE_WITHOUT_NUMPY],
        capture_output=True, text=True, timeout=120, check=True,
    )  # fmt: skip
    assert out.stdout.split() == ["hi", "False"], out.stdout + out.stderr


def test_serializers_are_made_on_first_use_and_match_rosbags_own() -> None:
    from rosbags.typesys.store import Typestore

    from rosl.idl import registry

    store = registry.store()
    odometry = get_message_class("nav_msgs/msg/Odometry")(child_frame_id="base")
    odometry.pose.covariance[3] = 2.5
    data = store.serialize(odometry)
    lazy = store._typestore
    made = vars(lazy.get_msgdef("nav_msgs/msg/Odometry"))
    assert "serialize_cdr_le" in made
    assert "serialize_ros1" not in made
    assert "deserialize_cdr_be" not in made

    eager = Typestore()  # rosbags' own: every function made at once
    eager.fielddefs.update(lazy.fielddefs)
    eager.types.update(lazy.types)
    wire = store.deserialize(data, "nav_msgs/msg/Odometry")
    assert wire == odometry
    for name in ("serialize_cdr", "serialize_ros1"):
        extra = {"little_endian": False} if name == "serialize_cdr" else {}
        ours = bytes(getattr(lazy, name)(odometry, "nav_msgs/msg/Odometry", **extra))
        theirs = bytes(getattr(eager, name)(odometry, "nav_msgs/msg/Odometry", **extra))
        assert ours == theirs, name
    ros1 = lazy.cdr_to_ros1(data, "nav_msgs/msg/Odometry")
    assert bytes(lazy.ros1_to_cdr(ros1, "nav_msgs/msg/Odometry")) == data
