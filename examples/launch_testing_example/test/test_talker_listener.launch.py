"""The talker and listener as ROS 2 tests them: active tests while they run, checks after.

rosl launch_test examples/launch_testing_example/test/test_talker_listener.launch.py
python -m pytest examples/launch_testing_example/test
"""

import unittest

import launch
import launch_ros.actions
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import pytest


@pytest.mark.launch_test
def generate_test_description():
    talker = launch_ros.actions.Node(
        package="launch_testing_example",
        executable="talker",
        output="screen",
        parameters=[{"min_subscribers": 1}],  # start once the listener listens
    )
    listener = launch_ros.actions.Node(
        package="launch_testing_example", executable="listener", output="screen"
    )
    description = launch.LaunchDescription([talker, listener, launch_testing.actions.ReadyToTest()])
    return description, {"talker": talker, "listener": listener}


class TestTalkerListener(unittest.TestCase):
    def test_talker_publishes(self, proc_output, talker):
        proc_output.assertWaitFor('Publishing: "Hello World: 3"', process=talker, timeout=30)

    def test_listener_hears_the_talker(self, proc_output):
        proc_output.assertWaitFor("I heard: [Hello World: 3]", process="listener", timeout=30)


@launch_testing.post_shutdown_test()
class TestTalkerListenerAfterShutdown(unittest.TestCase):
    def test_every_process_exited_cleanly(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info)

    def test_listener_heard_every_message_in_order(self, proc_output, listener):
        with launch_testing.asserts.assertSequentialStdout(proc_output, process=listener) as cm:
            for index in range(4):
                cm.assertInStdout(f"I heard: [Hello World: {index}]")
