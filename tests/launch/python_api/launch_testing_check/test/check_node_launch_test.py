"""A node started late by a TimerAction is found in the graph by a test's own rclpy node
(after ros2/examples' check_node_launch_test.py)."""

import time
import unittest

import launch
import launch.actions
import launch_ros.actions
import launch_testing.actions
import launch_testing.markers
import pytest
import rclpy
from rclpy.node import Node


@pytest.mark.launch_test
@launch_testing.markers.keep_alive
def generate_test_description():
    return launch.LaunchDescription(
        [
            launch.actions.TimerAction(
                period=1.0,
                actions=[
                    launch_ros.actions.Node(
                        package="demo_nodes_py", executable="talker", name="late_talker"
                    ),
                ],
            ),
            launch_testing.actions.ReadyToTest(),
        ]
    )


def wait_for_node(probe, name, timeout):
    start = time.time()
    while time.time() - start < timeout:
        if name in probe.get_node_names():
            return True
        time.sleep(0.1)
    return False


class TestLateNode(unittest.TestCase):
    def test_node_appears(self, proc_output):
        rclpy.init()
        try:
            probe = Node("check_node_probe")
            assert wait_for_node(probe, "late_talker", 30.0), "late_talker not found"
        finally:
            rclpy.shutdown()
