"""A shell process prints a greeting; the active test waits for it, the post-shutdown test
checks the exit codes (after ros2/examples' hello_world_launch_test.py)."""

import unittest

import launch
import launch.actions
import launch_testing.actions
import launch_testing.markers
import pytest


@pytest.mark.launch_test
@launch_testing.markers.keep_alive
def generate_test_description():
    return launch.LaunchDescription(
        [
            launch.actions.ExecuteProcess(cmd=["echo", "greetings_from_the_shell"], shell=True),
            launch_testing.actions.ReadyToTest(),
        ]
    )


class TestGreeting(unittest.TestCase):
    def test_greeting_on_stdout(self, proc_output):
        proc_output.assertWaitFor("greetings_from_the_shell", timeout=20, stream="stdout")


@launch_testing.post_shutdown_test()
class TestGreetingAfterShutdown(unittest.TestCase):
    def test_exit_codes(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info)
