"""Three nodes of one executable, found by name; a name never launched is not
(after ros2/examples' check_multiple_nodes_launch_test.py, with EnableRmwIsolation)."""

import time
import unittest

import launch
import launch_ros.actions
import launch_testing.actions
import launch_testing.markers
import pytest
import rclpy
from launch_testing_ros.actions import EnableRmwIsolation
from rclpy.node import Node


class WaitForNodes:
    def __init__(self, names, timeout=30.0):
        self.names = names
        self.timeout = timeout
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = Node("wait_for_nodes_probe", context=self.context)

    def wait(self):
        start = time.time()
        while time.time() - start < self.timeout:
            if all(name in self.node.get_node_names() for name in self.names):
                return True
            time.sleep(0.1)
        return False

    def missing(self):
        return set(self.names) - set(self.node.get_node_names())

    def shutdown(self):
        self.node.destroy_node()
        rclpy.shutdown(context=self.context)


@pytest.mark.launch_test
@launch_testing.markers.keep_alive
def generate_test_description():
    actions = [EnableRmwIsolation()]
    names = []
    for index in range(3):
        names.append(f"demo_node_{index}")
        actions.append(
            launch_ros.actions.Node(package="demo_nodes_py", executable="talker", name=names[-1])
        )
    actions.append(launch_testing.actions.ReadyToTest())
    return launch.LaunchDescription(actions), {"node_list": names}


class CheckMultipleNodes(unittest.TestCase):
    def test_all_nodes_found(self, node_list):
        waiter = WaitForNodes(node_list)
        try:
            assert waiter.wait()
            assert waiter.missing() == set()
        finally:
            waiter.shutdown()

    def test_a_node_never_launched_is_missing(self, node_list):
        waiter = WaitForNodes([*node_list, "invalid_node"], timeout=3.0)
        try:
            assert not waiter.wait()
            assert waiter.missing() == {"invalid_node"}
        finally:
            waiter.shutdown()
