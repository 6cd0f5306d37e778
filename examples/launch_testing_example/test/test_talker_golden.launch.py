"""The talker's run recorded and compared with a golden bag (rosl.testing).

``keep_alive``: the talker exits after five messages, the launch (and the recorder) stays up
until the active test has seen it. Regenerate the golden bag after an intended change with
``ROSL_REGENERATE_GOLDEN=1 rosl launch_test <this file>`` (or ``pytest --rosl-regenerate-golden``).
"""

import unittest
from pathlib import Path

import launch
import launch_ros.actions
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import launch_testing.markers
import pytest

from rosl.testing import Record, assert_matches_golden

GOLDEN = Path(__file__).parent / "golden" / "talker"


@pytest.mark.launch_test
@launch_testing.markers.keep_alive
def generate_test_description():
    record = Record()  # everything on the bus, into a fresh folder
    talker = launch_ros.actions.Node(
        package="launch_testing_example",
        executable="talker",
        output="screen",
        parameters=[{"count": 5, "period": 0.05, "min_subscribers": 1}],  # once recorded
    )
    description = launch.LaunchDescription([record, talker, launch_testing.actions.ReadyToTest()])
    return description, {"talker": talker, "bag": record.output}


class TestTalkerRun(unittest.TestCase):
    def test_talker_sends_five_messages_and_exits(self, proc_info, proc_output, talker):
        proc_info.assertWaitForShutdown(process=talker, timeout=30)
        proc_output.assertWaitFor('Publishing: "Hello World: 4"', process=talker, timeout=1)


@launch_testing.post_shutdown_test()
class TestTalkerRecording(unittest.TestCase):
    def test_talker_exited_cleanly(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info)

    def test_the_run_matches_the_golden_bag(self, bag):
        assert_matches_golden(bag, GOLDEN, topics=["/chatter"])
