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


def test_read_points_skips_nans_picks_fields_and_uvs_and_reshapes_organized_clouds() -> None:
    from sensor_msgs_py import point_cloud2
    from std_msgs.msg import Header

    xyz = np.arange(12, dtype=np.float32).reshape(4, 3)
    xyz[1, 2] = np.nan
    cloud = point_cloud2.create_cloud_xyz32(Header(), xyz)
    assert len(point_cloud2.read_points(cloud, skip_nans=True)) == 3
    assert point_cloud2.read_points(cloud, field_names=["y"], uvs=[0, 3])["y"].tolist() == [1, 10]
    assert np.array_equal(point_cloud2.read_points_numpy(cloud, field_names=["x", "y"]), xyz[:, :2])
    listed = point_cloud2.read_points_list(cloud, field_names=["x"])
    assert listed[2].x == 6.0
    grid = np.zeros((2, 3), dtype=point_cloud2.dtype_from_fields(_fields()))
    organized = point_cloud2.create_cloud(Header(), _fields(), grid)
    assert (organized.height, organized.width) == (2, 3)
    assert point_cloud2.read_points(organized, reshape_organized_cloud=True).shape == (2, 3)


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
    with pytest.raises(PointCloudError, match="needs fields of one datatype"):
        point_cloud2.read_points_numpy(point_cloud2.create_cloud(Header(), _fields(), []))
    with pytest.raises(PointCloudError, match="one column for each of the 3 fields"):
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
