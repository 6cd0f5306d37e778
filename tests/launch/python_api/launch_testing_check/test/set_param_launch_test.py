"""A parameter of a launched node set through its set_parameters service
(after ros2/examples' set_param_launch_test.py)."""

import unittest

import launch
import launch_ros.actions
import launch_testing.actions
import launch_testing.markers
import pytest
import rclpy
from rcl_interfaces.srv import SetParameters
from rclpy.node import Node


@pytest.mark.launch_test
@launch_testing.markers.keep_alive
def generate_test_description():
    return launch.LaunchDescription(
        [
            launch_ros.actions.Node(
                package="tutorial_pkg", executable="timer_node", name="demo_node_1", output="screen"
            ),
            launch_testing.actions.ReadyToTest(),
        ]
    )


class TestSetParameter(unittest.TestCase):
    def setUp(self):
        rclpy.init()
        self.node = Node("test_node")

    def tearDown(self):
        self.node.destroy_node()
        rclpy.shutdown()

    def test_set_parameter(self, proc_output):
        parameters = [rclpy.Parameter("timer_period_s", value=0.5).to_parameter_msg()]
        client = self.node.create_client(SetParameters, "demo_node_1/set_parameters")
        if not client.wait_for_service(timeout_sec=30.0):
            raise RuntimeError("Wait for service timed out")
        request = SetParameters.Request()
        request.parameters = parameters
        future = client.call_async(request)
        rclpy.spin_until_future_complete(self.node, future, timeout_sec=30.0)
        response = future.result()
        assert response.results[0].successful, "Could not set parameter!"
        proc_output.assertWaitFor("Timer period changed to 0.5 s", timeout=30)
