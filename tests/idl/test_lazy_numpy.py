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
