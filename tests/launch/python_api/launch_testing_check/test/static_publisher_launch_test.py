"""A node under test runs to its end beside other nodes kept alive, its actions shared through
``locals()`` (after geometry2's test_tf2 static_publisher.launch.py)."""

import unittest

import launch_testing
import launch_testing.actions
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_test_description():
    node_under_test = Node(
        package="demo_nodes_py",
        executable="add_two_ints_client",
        output="screen",
        arguments=[],
    )
    server = Node(package="demo_nodes_py", executable="add_two_ints_server", output="screen")
    return LaunchDescription(
        [
            server,
            node_under_test,
            launch_testing.util.KeepAliveProc(),
            launch_testing.actions.ReadyToTest(),
        ]
    ), locals()


class TestClient(unittest.TestCase):
    def test_termination(self, node_under_test, proc_info):
        proc_info.assertWaitForShutdown(process=node_under_test, timeout=60)


@launch_testing.post_shutdown_test()
class TestClientAfterShutdown(unittest.TestCase):
    def test_exit_code(self, proc_info, node_under_test):
        launch_testing.asserts.assertExitCodes(proc_info, process=node_under_test)
