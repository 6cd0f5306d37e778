"""launch_testing under rosl: ``rosl launch_test`` and pytest run ROS 2 launch tests.

The example package's two launch tests run for real (rosl launch_test and pytest); broken test
files give one line, failing tests give unittest's report with the user's frames only; the
asserts and process lookup are checked on recorded output without launching anything.
"""

from __future__ import annotations

import importlib.metadata
import os
import re
import sys
import threading
import time
from typing import TYPE_CHECKING

import pytest

from rosl.launch.testing import asserts
from rosl.launch.testing.io_handler import ActiveIoHandler, IoHandler, ProcessIO
from rosl.launch.testing.proc_info_handler import ProcessExited, ProcInfoHandler
from rosl.launch.testing.pytest.hooks import is_launch_test
from rosl.launch.testing.util import NO_CMD_ARGS, resolveProcesses
from tests.conftest import REPO
from tests.launch.support import EXAMPLES, Output, assert_all_gone, one_error_line, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Rosl

TESTS = EXAMPLES / "launch_testing_example" / "test"
FAILING = """
import sys
import unittest

import launch
import launch.actions
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import pytest

WORKER = "import sys, time\\nprint('ready', flush=True)\\nprint('on stderr', file=sys.stderr, flush=True)\\ntime.sleep(60)\\n"


@pytest.mark.launch_test
def generate_test_description():
    worker = launch.actions.ExecuteProcess(cmd=[sys.executable, "-c", WORKER], name="worker", output="screen")
    return launch.LaunchDescription([
        launch.actions.DeclareLaunchArgument("word", default_value="unset"),
        worker,
        launch_testing.actions.ReadyToTest(),
    ]), {"worker": worker}


class TestActive(unittest.TestCase):
    def test_gets_the_launch_argument(self, test_args):
        self.assertEqual(test_args, {"word": "hello"})

    def test_sees_ready_on_stdout(self, proc_output, worker):
        proc_output.assertWaitFor("ready", process=worker, timeout=20, stream="stdout")

    def test_waits_for_text_never_printed(self, proc_output):
        proc_output.assertWaitFor("never printed", process="worker", timeout=1)

    def test_fails(self):
        self.assertEqual(1 + 1, 3)


@launch_testing.post_shutdown_test()
class TestAfter(unittest.TestCase):
    def test_worker_was_stopped(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info, allowable_exit_codes=[-2], process="worker")
"""
DIES_EARLY = """
import sys
import unittest

import launch
import launch.actions
import launch_testing.actions
import pytest


@pytest.mark.launch_test
def generate_test_description():
    quitter = launch.actions.ExecuteProcess(
        cmd=[sys.executable, "-c", "import sys; print('bye'); sys.exit(3)"], name="quitter")
    return launch.LaunchDescription([quitter, launch_testing.actions.ReadyToTest()])


class TestActive(unittest.TestCase):
    def test_waits(self, proc_output):
        proc_output.assertWaitFor("never printed", timeout=60)
"""
KEPT_ALIVE = """
import sys
import time
import unittest

import launch
import launch.actions
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import launch_testing.markers
import pytest


@pytest.mark.launch_test
@launch_testing.markers.keep_alive
def generate_test_description():
    quitter = launch.actions.ExecuteProcess(
        cmd=[sys.executable, "-c", "import sys; print('bye'); sys.exit(3)"], name="quitter")
    return launch.LaunchDescription([quitter, launch_testing.actions.ReadyToTest()])


class TestActive(unittest.TestCase):
    def test_outlives_the_process(self, proc_info, proc_output):
        proc_info.assertWaitForShutdown(process="quitter", timeout=30)
        time.sleep(1)  # the launch stays up anyway: nothing to wait for but this test
        proc_output.assertWaitFor("bye", process="quitter", stream="stdout", timeout=1)


@launch_testing.post_shutdown_test()
class TestAfter(unittest.TestCase):
    def test_exit_code(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info, allowable_exit_codes=[3])
"""
NO_READY = """
import launch
import pytest


@pytest.mark.launch_test
def generate_test_description():
    return launch.LaunchDescription([])
"""
NO_FUNCTION = """
import unittest


class TestNothing(unittest.TestCase):
    def test_nothing(self):
        pass
"""


def _traceback_files(text: str) -> list[str]:
    return re.findall(r'^\s*File "([^"]+)"', text, flags=re.M)


# --- the example package, for real ------------------------------------------------------------


def test_the_example_passes_under_rosl_launch_test(rosl: Rosl) -> None:
    test = TESTS / "test_talker_listener.launch.py"
    output = rosl.start("launch_test", str(test))
    code = output.finish(90)
    text = output.both()
    assert code == 0, text
    for name in (
        "TestTalkerListener.test_talker_publishes",
        "TestTalkerListener.test_listener_hears_the_talker",
        "TestTalkerListenerAfterShutdown.test_every_process_exited_cleanly",
        "TestTalkerListenerAfterShutdown.test_listener_heard_every_message_in_order",
    ):
        assert re.search(rf"^{name.split('.')[1]} \(.*{name}\) \.\.\. ok$", text, re.M), text
    assert text.count("\nOK") == 2, text  # the active and the post-shutdown results
    assert sorted(output.started()) == ["listener-2", "talker-1"]
    assert_all_gone(output.pids())


def test_the_examples_pass_under_pytest_with_the_golden_bag(rosl: Rosl, tmp_path: Path) -> None:
    command = [sys.executable, "-m", "pytest", "-s", "-p", "no:cacheprovider", str(TESTS)]
    output = Output(rosl.processes.start(command, env={"TMPDIR": str(tmp_path)}))  # the run's bag
    rosl.watched.append(output)
    code = output.finish(120)
    text = output.both()
    assert code == 0, text
    assert re.search(r"^=+ 2 passed", text, re.M), text
    assert "test_the_run_matches_the_golden_bag" in text
    assert "rosbag2_recorder" in " ".join(output.started()), text  # the run was recorded
    assert list(tmp_path.glob("rosl_record_*/bag/metadata.yaml")), text
    assert_all_gone(output.pids())


def test_the_pytest_plugin_is_registered_by_the_installed_entry_point() -> None:
    plugins = {e.name: e.value for e in importlib.metadata.entry_points(group="pytest11")}
    assert plugins.get("rosl.launch_testing") == "rosl.launch.testing.pytest.hooks"


# --- mistakes and failures --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        (NO_FUNCTION, "no generate_test_description() function"),
        (NO_READY, "containing a launch_testing.actions.ReadyToTest() action"),
        ("import launch\ndef generate_test_description(:\n", ":2:31: syntax error: invalid syntax"),
    ],
)
def test_a_broken_launch_test_file_is_one_line(
    rosl: Rosl, launch_dir: Path, source: str, expected: str
) -> None:
    path = write_launch(launch_dir, "test_broken.launch.py", source)
    code, out, err = rosl.run("launch_test", str(path))
    assert code == 1, out + err
    line = one_error_line(err)
    assert line.startswith(str(path)), line
    assert expected in line
    assert "process started" not in out


def test_failing_tests_fail_the_run_with_only_the_users_frames(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "test_failing.launch.py", FAILING)
    output = rosl.start("launch_test", str(path), "word:=hello")
    code = output.finish(90)
    text = output.both()
    assert code == 1, text
    for passed in ("test_gets_the_launch_argument", "test_sees_ready_on_stdout",
                   "test_worker_was_stopped"):  # fmt: skip
        assert re.search(rf"^{passed} \(.*\) \.\.\. ok$", text, re.M), text
    assert "AssertionError: 2 != 3" in text
    assert (
        "AssertionError: Waiting for output timed out: 'never printed' not seen on the stderr "
        "of worker-1 within 1 s; the last lines:\n    on stderr"
    ) in text
    assert "FAILED (failures=2)" in text
    assert set(_traceback_files(text)) == {str(path)}, text  # no frame of rosl's
    assert_all_gone(output.pids())


def test_pytest_reports_each_failed_test_of_a_launch_test(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(launch_dir, "test_failing.launch.py", FAILING)
    command = [sys.executable, "-m", "pytest", "-s", "-p", "no:cacheprovider", str(path),
               "--launch-args", "word:=hello"]  # fmt: skip
    output = Output(rosl.processes.start(command, cwd=launch_dir))
    rosl.watched.append(output)
    code = output.finish(90)
    text = output.both()
    assert code == 1, text
    assert "2 failed: TestActive.test_fails, TestActive.test_waits_for_text_never_printed" in text
    assert re.search(r"^FAILED .*test_failing\.launch\.py::test_failing\.launch - 2 failed", text,
                     re.M), text  # fmt: skip
    assert_all_gone(output.pids())


def test_a_launch_that_ends_before_its_active_tests_fails_the_run(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "test_dies.launch.py", DIES_EARLY)
    output = rosl.start("launch_test", str(path))
    code = output.finish(30)  # long before the active test's own 60 s
    text = output.both()
    assert code == 1, text
    assert "Processes under test stopped before tests completed" in text
    assert "Process 'quitter-1' exited with 3\n##### 'quitter-1' output #####\nbye" in text
    assert_all_gone(output.pids())


def test_keep_alive_keeps_the_launch_up_until_the_active_tests_end(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "test_kept.launch.py", KEPT_ALIVE)
    output = rosl.start("launch_test", str(path))
    code = output.finish(60)
    text = output.both()
    assert code == 0, text
    assert re.search(r"^test_outlives_the_process \(.*\) \.\.\. ok$", text, re.M), text
    assert re.search(r"^test_exit_code \(.*\) \.\.\. ok$", text, re.M), text


# --- asserts and process lookup, on recorded output ------------------------------------------


class Recorded:
    """Three exited processes and what they printed, as the runner records them."""

    def __init__(self) -> None:
        self.talker, self.listener, self.tool = object(), object(), object()
        self.io = IoHandler()
        self.info = ProcInfoHandler()
        for action, name, cmd, code in (
            (self.talker, "talker-1", ["talker"], 0),
            (self.listener, "listener-2", ["listener", "--fast"], 0),
            (self.tool, "talker_tool-3", ["talker_tool", "-x"], 1),
        ):
            self.io.track(action, {"name": name, "cmd": cmd, "pid": 1})
            self.info.append(ProcessExited(action, name, 1, cmd, code))

    def say(self, action: object, text: str, fd: int = 2) -> None:
        name = self.io.process_details(action)["name"]
        self.io.append(ProcessIO(action, name, 1, text.encode() + b"\n", fd))


def test_exit_codes_are_checked_for_every_process_or_the_one_named() -> None:
    run = Recorded()
    with pytest.raises(AssertionError, match=r"^Proc talker_tool-3 exited with code 1$"):
        asserts.assertExitCodes(run.info)
    asserts.assertExitCodes(run.info, allowable_exit_codes=[0, 1])
    asserts.assertExitCodes(run.info, process="listener")
    asserts.assertExitCodes(run.info, process=run.talker)


def test_a_name_matches_part_of_a_label_and_must_be_unique_unless_narrowed() -> None:
    run = Recorded()
    with pytest.raises(ValueError, match="Found multiple processes matching name 'talker'"):
        resolveProcesses(run.info, process="talker")
    assert resolveProcesses(run.info, process="talker", cmd_args=NO_CMD_ARGS) == [run.talker]
    assert resolveProcesses(run.info, process="talker", cmd_args="-x") == [run.tool]
    assert resolveProcesses(run.info, process="listener", cmd_args=["--fast"]) == [run.listener]
    assert len(resolveProcesses(run.info, process="talker", strict_proc_matching=False)) == 2


def test_output_asserts_look_in_one_stream_and_accept_text_regex_and_sequences() -> None:
    run = Recorded()
    run.say(run.listener, "I heard: \x1b[1m[Hello World: 1]\x1b[0m")
    run.say(run.listener, "printed on stdout", fd=1)
    asserts.assertInStderr(run.io, "I heard: [Hello World: 1]", "listener")
    asserts.assertInStdout(run.io, re.compile(r"printed on \w+"), "listener")
    asserts.assertInStream(run.io, ["I heard", "World: 1"], "listener")
    with pytest.raises(AssertionError, match="in the stdout of any of the matching processes"):
        asserts.assertInStdout(run.io, "I heard", "listener")
    with pytest.raises(AssertionError):
        asserts.assertInStream(run.io, ["World: 1", "I heard"], "listener")


def test_sequential_output_must_come_in_the_order_asked() -> None:
    run = Recorded()
    for index in range(3):
        run.say(run.listener, f"I heard: [Hello World: {index}]")
    with asserts.assertSequentialStdout(run.io, "listener") as cm:
        cm.assertInStdout("World: 0")
        cm.assertInStdout("World: 2")
    with asserts.assertSequentialStdout(run.io, "listener") as cm:
        cm.assertInStdout("World: 2")
        with pytest.raises(AssertionError, match="'World: 1' not found in sequence after prev"):
            cm.assertInStdout("World: 1")


def test_wait_for_returns_when_the_line_arrives_from_the_supervising_thread() -> None:
    output = ActiveIoHandler()
    action = object()
    output.track(action, {"name": "talker-1", "cmd": ["talker"], "pid": 1})

    def later() -> None:
        time.sleep(0.2)
        output.append(ProcessIO(action, "talker-1", 1, b"Publishing: 3\n", 2))

    thread = threading.Thread(target=later)
    thread.start()
    start = time.monotonic()
    output.assertWaitFor("Publishing: 3", process="talker", timeout=60)
    assert time.monotonic() - start < 30  # woken by the line, not by the timeout
    thread.join(10)
    with pytest.raises(AssertionError, match=r"the last lines:\n    Publishing: 3$"):
        output.assertWaitFor("Publishing: 4", process="talker", timeout=0.1)


def test_only_files_marking_generate_test_description_are_launch_tests(launch_dir: Path) -> None:
    marked = write_launch(launch_dir, "test_a.launch.py", NO_READY)
    unmarked = write_launch(launch_dir, "test_b.py", "def generate_test_description():\n    pass\n")
    assert is_launch_test(marked)
    assert not is_launch_test(unmarked)
    assert not [p for p in (REPO / "tests").rglob("test_*.py") if is_launch_test(p)]


ROS_STYLE = """
import shutil
import tempfile
import unittest
from pathlib import Path

import launch
import launch_ros.actions
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import pytest
from launch_testing_ros import WaitForTopics
from std_msgs.msg import String

BAG = Path(tempfile.mkdtemp()) / "run"


@pytest.mark.launch_test
def generate_test_description():
    talker = launch_ros.actions.Node(
        package="launch_testing_example", executable="talker", output="screen",
        parameters=[{"count": 1000}],
    )
    record = launch.actions.ExecuteProcess(
        cmd=["ros2", "bag", "record", "/chatter", "-o", str(BAG)], output="screen"
    )
    hello = launch.actions.ExecuteProcess(cmd=["echo", "hello_world"], output="screen")
    return launch.LaunchDescription([
        record, talker, hello, launch_testing.actions.ReadyToTest(),
    ]), {"record": record, "hello": hello}


class TestAsRos2ExamplesDo(unittest.TestCase):
    def test_the_talker_publishes(self):
        with WaitForTopics([("chatter", String)], timeout=20.0) as wait_for_topics:
            self.assertEqual(wait_for_topics.topics_received(), {"chatter"})
            self.assertTrue(wait_for_topics.received_messages("chatter")[0].data)

    def test_echo_says_hello(self, proc_output, hello):
        proc_output.assertWaitFor("hello_world", process=hello, timeout=10, stream="stdout")

    def test_the_recorder_subscribed(self, proc_output, record):
        proc_output.assertWaitFor("Subscribed to topic '/chatter'", process=record, timeout=20)


@launch_testing.post_shutdown_test()
class TestAfter(unittest.TestCase):
    def test_every_process_ended_well(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info, allowable_exit_codes=[0, -2, 130])

    def test_the_bag_holds_chatter(self):
        text = (BAG / "metadata.yaml").read_text()
        self.assertIn("name: /chatter", text)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(BAG.parent, ignore_errors=True)
"""


def test_a_launch_test_in_ros2_examples_style_waits_for_topics_and_records_with_ros2_bag(
    rosl: Rosl, launch_dir: Path
) -> None:
    # launch_testing_ros.WaitForTopics, `ros2 bag record` in an ExecuteProcess (rosl's words where
    # no ros2 is installed) and echo, as ros2/examples' launch_testing_examples use them
    path = write_launch(launch_dir, "test_ros_style.launch.py", ROS_STYLE)
    code, out, err = rosl.run("launch_test", str(path), timeout=120.0)
    assert code == 0, out + err
    assert re.search(r"Ran 3 tests in .*\n\nOK", out + err), out + err


ONLY_AFTER = """
import unittest

import launch
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import pytest


@pytest.mark.launch_test
def generate_test_description():
    return launch.LaunchDescription([
        # ends at once; ignores the SIGINT of a shutdown that may come as it ends (that race,
        # launch_testing's own, is not what this test is about)
        launch.actions.ExecuteProcess(cmd=["sh", "-c", "trap '' INT; echo from_a"],
                                      output="screen", name="echo"),
        launch_testing.actions.ReadyToTest(),
    ])


@launch_testing.post_shutdown_test()
class TestAfter(unittest.TestCase):
    def test_exit_codes(self, proc_info):
        launch_testing.asserts.assertExitCodes(proc_info)
"""


def test_a_launch_test_with_only_post_shutdown_tests_passes_however_fast_its_process_ends(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "test_only_after.launch.py", ONLY_AFTER)
    for _ in range(3):  # the echo ends at once: the run must not outrun the (empty) active tests
        code, out, err = rosl.run("launch_test", str(path))
        assert code == 0, out + err


def test_a_ros2_launch_testing_plugin_installed_beside_makes_rosl_step_aside(
    tmp_path: Path,
) -> None:
    import subprocess

    site = tmp_path / "site"
    info = site / "ros2_launch_testing-1.0.dist-info"  # ROS 2's plugin, as a sourced ROS 2 has it
    info.mkdir(parents=True)
    (info / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: ros2-launch-testing\nVersion: 1.0\n"
    )
    (info / "entry_points.txt").write_text("[pytest11]\nlaunch_testing = fake_ros2_plugin\n")
    (site / "fake_ros2_plugin.py").write_text(
        "def pytest_addoption(parser):\n"
        "    parser.addoption('--launch-args', action='append', nargs='*', default=[])\n"
    )
    (tmp_path / "test_plain.py").write_text("def test_plain():\n    assert True\n")
    run = (  # its folder after rosl's on the path: rosl's plugin registers first
        f"import sys; sys.path.append({str(site)!r}); import pytest; "
        "sys.exit(pytest.main(['-q', '-p', 'no:cacheprovider', 'test_plain.py']))"
    )
    result = subprocess.run(
        [sys.executable, "-c", run], cwd=tmp_path, env=dict(os.environ),
        capture_output=True, text=True, timeout=120, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    assert "1 passed" in result.stdout
