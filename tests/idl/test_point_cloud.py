"""sensor_msgs_py.point_cloud2 under rosl, as upstream's tests and real nodes use it."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import numpy as np
import pytest

import rosl.compat
from rosl.idl.errors import PointCloudError

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.conftest import Processes

rosl.compat.install()


def _fields() -> list[object]:
    from sensor_msgs.msg import PointField

    return [
        PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=1),
        PointField(name="y", offset=4, datatype=PointField.FLOAT32, count=1),
        PointField(name="z", offset=8, datatype=PointField.FLOAT32, count=1),
        PointField(name="ring", offset=12, datatype=PointField.UINT16, count=1),
    ]


def test_create_cloud_from_a_structured_array_reads_back_equal() -> None:
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    dtype = point_cloud2.dtype_from_fields(_fields())
    points = np.zeros(1000, dtype=dtype)
    points["x"] = np.arange(1000)
    points["ring"] = 3
    cloud = point_cloud2.create_cloud(Header(frame_id="lidar"), _fields(), points)
    assert (cloud.height, cloud.width, cloud.point_step, cloud.row_step) == (1, 1000, 14, 14000)
    assert cloud.is_bigendian == (sys.byteorder != "little")
    back = point_cloud2.read_points(cloud)
    assert back.dtype.names == ("x", "y", "z", "ring")
    assert np.array_equal(back, points)
    points["x"] = -1  # the cloud owns its bytes
    assert point_cloud2.read_points(cloud)["x"][5] == 5


def test_read_points_skips_nans_picks_fields_and_uvs() -> None:
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    xyz = np.arange(12, dtype=np.float32).reshape(4, 3)
    xyz[1, 2] = np.nan
    cloud = point_cloud2.create_cloud_xyz32(Header(), xyz)
    assert len(point_cloud2.read_points(cloud)) == 4
    assert len(point_cloud2.read_points(cloud, skip_nans=True)) == 3
    assert point_cloud2.read_points(cloud, field_names=["y"], uvs=[0, 3])["y"].tolist() == [1, 10]
    assert np.array_equal(point_cloud2.read_points_numpy(cloud, field_names=["x", "y"]), xyz[:, :2])
    listed = point_cloud2.read_points_list(cloud, field_names=["x"])
    assert listed[2].x == 6.0


def _hand_built(width: int, height: int, fields: list[object], data: bytes, step: int) -> object:
    from sensor_msgs.msg import PointCloud2
    from std_msgs.msg import Header

    return PointCloud2(
        header=Header(frame_id="frame"), height=height, width=width, fields=fields,
        is_bigendian=sys.byteorder != "little", point_step=step, row_step=step * width,
        data=data, is_dense=False,
    )  # fmt: skip


def test_an_organized_cloud_has_sensor_msgs_pys_width_and_height_both_ways() -> None:
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    grid = np.arange(18, dtype=np.float32).reshape(2, 3, 3)  # sensor_msgs_py: width 2, height 3
    cloud = point_cloud2.create_cloud_xyz32(Header(frame_id="frame"), grid)
    assert cloud == _hand_built(2, 3, _fields()[:3], grid.tobytes(), 12)
    shaped = point_cloud2.read_points(cloud, reshape_organized_cloud=True)
    assert shaped.shape == (2, 3)
    assert np.array_equal(point_cloud2.read_points_numpy(cloud, reshape_organized_cloud=True), grid)


def test_a_field_with_a_count_reads_as_numbered_fields() -> None:
    from sensor_msgs.msg import PointField
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    fields = [PointField(name="x", offset=0, datatype=PointField.FLOAT32, count=3)]
    values = np.arange(18, dtype=np.float32).reshape(6, 3)
    cloud = point_cloud2.create_cloud(Header(frame_id="frame"), fields, values)
    assert cloud == _hand_built(6, 1, fields, values.tobytes(), 12)
    assert point_cloud2.read_points(cloud).dtype.names == ("x_0", "x_1", "x_2")
    assert np.array_equal(point_cloud2.read_points_numpy(cloud), values)


def test_mixed_types_and_padded_points_need_a_matching_dtype_and_point_step() -> None:
    from sensor_msgs.msg import PointField
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    fields = [
        PointField(name="a", offset=0, datatype=PointField.FLOAT32, count=1),
        PointField(name="b", offset=4, datatype=PointField.FLOAT64, count=1),
        PointField(name="c", offset=12, datatype=PointField.UINT8, count=1),
    ]
    mixed = np.array([(1.5, 2.5, 3), (4.5, 5.5, 6)], dtype=[("a", "f4"), ("b", "f8"), ("c", "u1")])
    cloud = point_cloud2.create_cloud(Header(frame_id="frame"), fields, mixed)
    assert cloud == _hand_built(2, 1, fields, mixed.tobytes(), 13)
    assert point_cloud2.read_points(cloud).dtype == mixed.dtype
    with pytest.raises(AssertionError, match="of one datatype"):
        point_cloud2.read_points_numpy(cloud)
    padded = np.zeros(3, dtype={"names": list("xyz"), "formats": ["f4"] * 3, "itemsize": 20})
    with pytest.raises(PointCloudError, match="does not match the PointFields"):
        point_cloud2.create_cloud(Header(), _fields()[:3], padded)
    cloud = point_cloud2.create_cloud(Header(), _fields()[:3], padded, 20)
    assert cloud.point_step == 20
    assert point_cloud2.read_points_numpy(cloud).shape == (3, 3)


def test_a_list_of_tuples_builds_the_same_cloud_as_an_array() -> None:
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    rows = [(0.0, 0.1, 0.2), (1.0, 1.1, 1.2), (2.0, np.nan, 2.2)]
    from_list = point_cloud2.create_cloud_xyz32(Header(frame_id="frame"), rows)
    from_array = point_cloud2.create_cloud(
        Header(frame_id="frame"), _fields()[:3], np.array(rows, dtype=np.float32)
    )
    assert from_list == from_array
    assert from_list == _hand_built(3, 1, _fields()[:3], np.array(rows, "f4").tobytes(), 12)


def test_a_big_endian_cloud_reads_in_this_machines_order() -> None:
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    cloud = point_cloud2.create_cloud_xyz32(Header(), np.zeros((2, 3), np.float32))
    cloud.is_bigendian = sys.byteorder == "little"
    values = np.arange(6, dtype=np.float32).reshape(2, 3)
    swapped = values.astype(">f4" if cloud.is_bigendian else "<f4").tobytes()
    cloud.data = swapped
    assert np.array_equal(point_cloud2.read_points_numpy(cloud), values)


def test_bad_clouds_are_errors_naming_the_problem() -> None:
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    cloud = point_cloud2.create_cloud_xyz32(Header(), np.zeros((4, 3), np.float32))
    with pytest.raises(PointCloudError, match="no field 'w'; its fields are: x, y, z"):
        point_cloud2.read_points(cloud, field_names=["w"])
    cloud.width = 10
    with pytest.raises(PointCloudError, match="fewer than its 10 points"):
        point_cloud2.read_points(cloud)
    with pytest.raises(AssertionError, match="needs fields of one datatype"):
        point_cloud2.read_points_numpy(point_cloud2.create_cloud(Header(), _fields(), []))
    with pytest.raises(PointCloudError, match="one column for each of the 3 values"):
        point_cloud2.create_cloud(Header(), _fields()[:3], np.zeros((3, 4)))
    with pytest.raises(PointCloudError, match="expects a sensor_msgs/msg/PointCloud2"):
        point_cloud2.read_points(Header())


PUBLISHER = """\
import numpy as np
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import PointCloud2, PointField
from sensor_msgs_py import point_cloud2
from std_msgs.msg import Header


class CloudPublisher(Node):
    def __init__(self):
        super().__init__('cloud_publisher')
        self.publisher = self.create_publisher(PointCloud2, 'cloud', 10)
        self.timer = self.create_timer(0.2, self.tick)
        fields = [PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1)
                  for i, n in enumerate('xyz')]
        points = np.zeros((20000, 3), dtype=np.float32)
        points[:, 0] = np.arange(20000)
        self.cloud = point_cloud2.create_cloud(Header(frame_id='lidar'), fields, points)

    def tick(self):
        self.cloud.header.stamp = self.get_clock().now().to_msg()
        self.publisher.publish(self.cloud)


def main():
    rclpy.init()
    rclpy.spin(CloudPublisher())
"""

SUBSCRIBER = """\
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import PointCloud2
from sensor_msgs_py import point_cloud2


class CloudSubscriber(Node):
    def __init__(self):
        super().__init__('cloud_subscriber')
        self.create_subscription(PointCloud2, 'cloud', self.on_cloud, 10)
        self.done = False

    def on_cloud(self, msg):
        points = point_cloud2.read_points(msg, field_names=['x', 'y', 'z'], skip_nans=True)
        xyz = point_cloud2.read_points_numpy(msg)
        print(msg.header.frame_id, len(points), int(xyz[:, 0].astype('int64').sum()), flush=True)
        self.done = True


def main():
    rclpy.init()
    node = CloudSubscriber()
    while rclpy.ok() and not node.done:
        rclpy.spin_once(node, timeout_sec=0.5)
    rclpy.shutdown()
"""


def test_a_node_publishing_create_cloud_reaches_a_node_reading_points(
    make_package: Callable[..., Path], workspace: Path, processes: Processes
) -> None:
    manifest = (
        '<?xml version="1.0"?>\n<package format="3">\n  <name>clouds</name>\n'
        "  <version>0.0.0</version>\n"
        "  <export><build_type>ament_python</build_type></export>\n</package>\n"
    )
    setup_py = (
        "from setuptools import setup\npackage_name = 'clouds'\nsetup(name=package_name,\n"
        "      entry_points={'console_scripts': [\n"
        "          'talker = ' + package_name + '.talker:main',\n"
        "          f'listener = {package_name}.listener:main']})\n"
    )
    files = {
        "setup.py": setup_py,
        "clouds/__init__.py": "",
        "clouds/talker.py": PUBLISHER,
        "clouds/listener.py": SUBSCRIBER,
    }
    make_package("clouds", files, manifest=manifest)
    listener = processes.rosl("run", "clouds", "listener", cwd=workspace)
    talker = processes.rosl("run", "clouds", "talker", cwd=workspace)
    try:
        out, err = listener.communicate(timeout=60)
    finally:
        processes.stop(talker)
    assert listener.returncode == 0, err
    assert out.splitlines() == [f"lidar 20000 {sum(range(20000))}"], err
