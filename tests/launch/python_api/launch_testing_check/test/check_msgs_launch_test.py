"""Messages on a launched node's topic, awaited with launch_testing_ros.WaitForTopics
(after ros2/examples' check_msgs_launch_test.py)."""

import unittest

import launch
import launch_ros.actions
import launch_testing.actions
import launch_testing.markers
import pytest
from launch_testing_ros import WaitForTopics
from std_msgs.msg import String


@pytest.mark.launch_test
@launch_testing.markers.keep_alive
def generate_test_description():
    return launch.LaunchDescription(
        [
            launch_ros.actions.Node(
                package="demo_nodes_py", executable="talker", name="msgs_talker"
            ),
            launch_testing.actions.ReadyToTest(),
        ]
    )


class TestMessages(unittest.TestCase):
    def test_chatter_has_messages(self):
        with WaitForTopics([("chatter", String)], timeout=30.0) as waiter:
            assert waiter.topics_received() == {"chatter"}
