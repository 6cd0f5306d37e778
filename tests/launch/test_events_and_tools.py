"""Events aimed at processes, OnExecutionComplete, LocalSubstitution, XML's on_exit and
booleans, FindExecutable('ros2'), errors located once, and launch_testing's tools, parametrize,
``-v`` and ``--junit-xml`` — each run for real (rosl launch / rosl launch_test).
"""

from __future__ import annotations

import re
import shutil
import sys
import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING

import pytest

from rosl.launch.testing.tools import (
    basic_output_filter,
    build_line_match,
    expect_output,
    expected_output_from_file,
)
from tests.launch.support import Output, assert_all_gone, one_error_line, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Rosl

EVENTS = """
import signal
import sys

from launch import LaunchDescription
from launch.actions import EmitEvent, ExecuteProcess, LogInfo, OpaqueFunction
from launch.actions import RegisterEventHandler, TimerAction
from launch.event_handlers import OnExecutionComplete, OnProcessExit
from launch.events import matches_action
from launch.events.process import ShutdownProcess, SignalProcess
from launch.substitutions import LocalSubstitution

TRAP = (
    "import signal, sys, time\\n"
    "signal.signal(signal.SIGUSR1, lambda *a: (print('got usr1', flush=True), sys.exit(3)))\\n"
    "print('trapping', flush=True)\\n"
    "time.sleep(60)\\n"
)


def generate_launch_description():
    sleeper = ExecuteProcess(cmd=[sys.executable, "-c", "import time; time.sleep(60)"],
                             name="sleeper")
    trap = ExecuteProcess(cmd=[sys.executable, "-c", TRAP], name="trap", output="screen")
    noted = OpaqueFunction(function=lambda context: None)
    return LaunchDescription([
        sleeper,
        trap,
        noted,
        RegisterEventHandler(OnExecutionComplete(
            target_action=noted, on_completion=[LogInfo(msg="opaque function complete")])),
        RegisterEventHandler(OnProcessExit(target_action=sleeper, on_exit=[
            LogInfo(msg=["sleeper exited with ", LocalSubstitution("event.returncode")])])),
        RegisterEventHandler(OnExecutionComplete(target_action=trap, on_completion=[
            LogInfo(msg="trap complete"),
            ExecuteProcess(cmd=[sys.executable, "-c", "print('after the trap')"],
                           name="after", output="screen"),
        ])),
        RegisterEventHandler(OnProcessExit(target_action=trap, on_exit=[
            LogInfo(msg=["trap exited with ", LocalSubstitution("event.returncode")])])),
        TimerAction(period=1.0, actions=[
            EmitEvent(event=ShutdownProcess(process_matcher=matches_action(sleeper))),
            EmitEvent(event=SignalProcess(signal_number=signal.SIGUSR1,
                                          process_matcher=matches_action(trap))),
        ]),
    ])
"""


def test_process_events_completion_and_local_substitution_run_in_a_launch(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "events.launch.py", EVENTS)
    launch = rosl.start("launch", str(path))
    code = launch.finish(90)
    out = launch.text()

    assert code is not None, launch.both()
    assert "[INFO] [launch.user]: opaque function complete" in out, launch.both()
    assert "[INFO] [launch.user]: sleeper exited with -2" in out, launch.both()
    assert "[trap-2] got usr1" in out, launch.both()
    assert "[INFO] [launch.user]: trap exited with 3" in out, launch.both()
    lines = launch.lines()
    complete = lines.index("[INFO] [launch.user]: trap complete")
    assert any("[after-3] after the trap" in line for line in lines[complete:]), launch.both()
    assert_all_gone(launch.pids())


def test_local_substitution_outside_an_event_handler_is_one_line_at_its_line(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "local.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import LogInfo
        from launch.substitutions import LocalSubstitution
        def generate_launch_description():
            return LaunchDescription([
                LogInfo(msg=LocalSubstitution("event.returncode")),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    line = one_error_line(err)
    assert line.startswith(f"{path}:6: LocalSubstitution('event.returncode'): no local 'event'"), (
        err
    )


def test_a_shutdown_process_event_needs_a_matcher(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "matcher.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import EmitEvent
        from launch.events.process import ShutdownProcess
        def generate_launch_description():
            return LaunchDescription([EmitEvent(event=ShutdownProcess(process_matcher="talker"))])
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err).startswith(
        f"{path}:5: ShutdownProcess(process_matcher=...) needs"
    ), err


def test_xml_on_exit_shutdown_ends_the_launch_when_that_process_ends(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "on_exit.launch.xml",
        """
        <launch>
          <executable cmd="sleep 60" name="long"/>
          <executable cmd="echo short" name="short" output="screen" on_exit="shutdown"/>
        </launch>
        """,
    )
    launch = rosl.start("launch", str(path))

    assert launch.finish(60) == 0, launch.both()
    assert "[short-2] short" in launch.text(), launch.both()
    assert re.search(r"\[long-1\]: process has (died|finished)", launch.text()), launch.both()
    assert_all_gone(launch.pids())


def test_xml_on_exit_other_than_shutdown_is_one_line(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "on_exit_bad.launch.xml",
        """
        <launch>
          <executable cmd="echo x" on_exit="restart"/>
        </launch>
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err) == (
        f"{path}:2: attribute 'on_exit' of <executable> can only be 'shutdown', not 'restart'"
    )


def test_xml_booleans_take_yaml_words_as_launch_reads_them(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "booleans.launch.xml",
        """
        <launch>
          <let name="shown" value="outer"/>
          <group scoped="no">
            <let name="shown" value="from the group"/>
          </group>
          <executable cmd="echo $(var shown) | tr a-z A-Z" shell="yes" output="screen"/>
          <executable cmd="echo off" shell="Off" output="screen" respawn="NO"/>
        </launch>
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 0, f"{out}\n{err}"
    assert "FROM THE GROUP" in out, out
    assert "] echo off" not in out, out
    assert "] off" in out, out


def test_an_xml_boolean_that_is_no_boolean_is_one_line(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "maybe.launch.xml",
        """
        <launch>
          <group scoped="maybe"/>
        </launch>
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err) == (
        f"{path}:2: attribute 'scoped' of <group> must be a boolean (true/false, yes/no, on/off), "
        "not 'maybe'"
    )


@pytest.mark.skipif(shutil.which("ros2") is not None, reason="a real ros2 is installed")
def test_find_executable_ros2_is_rosl_where_no_ros2_is_installed(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "ros2.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess
        from launch.substitutions import FindExecutable
        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd=[FindExecutable(name="ros2"), "interface", "show",
                                    "std_msgs/msg/String"], output="screen"),
                ExecuteProcess(cmd=[[FindExecutable(name="ros2"), " interface list -m"]],
                               shell=True, output="screen"),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 0, f"{out}\n{err}"
    assert re.search(r"^\[rosl-1\] string data", out, re.MULTILINE), out
    # a shell command is named as launch names it: its text after the last '/'
    assert re.search(r"^\[rosl interface list -m-2\]\s+std_msgs/msg/String$", out, re.MULTILINE)


def test_an_undeclared_var_in_an_included_file_names_its_file_and_line_once(
    rosl: Rosl, launch_dir: Path
) -> None:
    inner = write_launch(
        launch_dir,
        "inner.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import LogInfo
        from launch.substitutions import LaunchConfiguration
        def generate_launch_description():
            return LaunchDescription([
                LogInfo(msg=LaunchConfiguration("nope")),
            ])
        """,
    )
    outer = write_launch(
        launch_dir,
        "outer.launch.xml",
        '<launch>\n  <include file="$(dirname)/inner.launch.py"/>\n</launch>\n',
    )

    code, out, err = rosl.run("launch", str(outer))

    assert code == 1, f"{out}\n{err}"
    line = one_error_line(err)
    assert line.startswith(f"{inner}:6: launch configuration 'nope' is not set"), err
    assert str(outer) not in line, err
    assert line.count(str(inner)) == 1, err


@pytest.mark.parametrize("outer_format", ["xml", "py"])
def test_a_required_argument_of_an_included_file_is_reported_where_it_is_declared(
    rosl: Rosl, launch_dir: Path, outer_format: str
) -> None:
    inner = write_launch(
        launch_dir,
        "needs.launch.xml",
        """
        <launch>
          <arg name="needed" description="a needed thing"/>
          <log message="$(var needed)"/>
        </launch>
        """,
    )
    outer = write_launch(
        launch_dir,
        f"outer.launch.{outer_format}",
        '<launch>\n  <include file="$(dirname)/needs.launch.xml"/>\n</launch>\n'
        if outer_format == "xml"
        else f"""
        from launch import LaunchDescription
        from launch.actions import IncludeLaunchDescription
        from launch.launch_description_sources import AnyLaunchDescriptionSource
        def generate_launch_description():
            return LaunchDescription([
                IncludeLaunchDescription(AnyLaunchDescriptionSource({str(inner)!r})),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(outer))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err) == (
        f"{inner}:2: launch argument 'needed' is required (a needed thing); "
        "pass it as needed:=<value>"
    )


TOOLS_TEST = """
import functools
import re
import sys
import unittest

import launch
import launch_testing
import launch_testing.actions
import launch_testing.asserts
import launch_testing.markers
import launch_testing.tools
import launch_testing_ros.tools
import pytest
from launch.actions import ExecuteProcess
from launch_testing.tools.output import expect_output as expect_from_output
from launch_testing.tools.text import build_line_match


@pytest.mark.launch_test
@launch_testing.parametrize("word, count", [("alpha", 1), ("beta", 2)])
@launch_testing.markers.keep_alive
def generate_test_description(word, count):
    return launch.LaunchDescription([launch_testing.actions.ReadyToTest()]), {"given": word}


class TestTools(unittest.TestCase):
    def test_launch_process(self, launch_service, proc_info, proc_output, word, count, given):
        self.assertEqual(word, given)
        code = f"print('pid 1'); print('hello {word}'); print('count {count}')"
        action = ExecuteProcess(cmd=[sys.executable, "-c", code], output="screen")
        with launch_testing.tools.launch_process(
            launch_service, action, proc_info, proc_output,
            output_filter=launch_testing_ros.tools.basic_output_filter(
                filtered_rmw_implementation="rmw_fastrtps_cpp"),
        ) as command:
            self.assertTrue(command.wait_for_shutdown(timeout=30))
        self.assertEqual(command.exit_code, launch_testing.asserts.EXIT_OK)
        self.assertTrue(launch_testing.tools.expect_output(
            expected_lines=[f"hello {word}", f"count {count}"], text=command.output, strict=True
        ), command.output)
        self.assertTrue(expect_from_output(command.output, expected_lines=[f"count {count}"]))
        self.assertIsNotNone(build_line_match("count")(command.output.splitlines()))

    def test_wait_for_output_then_stop(self, launch_service, proc_info, proc_output):
        code = "import time\\nprint('ready', flush=True)\\ntime.sleep(60)"
        action = ExecuteProcess(cmd=[sys.executable, "-c", code])
        with launch_testing.tools.launch_process(
            launch_service, action, proc_info, proc_output
        ) as command:
            self.assertTrue(command.wait_for_output(functools.partial(
                launch_testing.tools.expect_output, expected_lines=[re.compile(r"rea.y")]
            ), timeout=30))
            self.assertTrue(command.running)
        self.assertTrue(command.wait_for_shutdown(timeout=30))

    def test_fails_for_beta(self, word):
        self.assertNotEqual(word, "beta")
"""


def test_tools_and_parametrize_run_under_launch_test_with_a_junit_report(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "test_tools.py", TOOLS_TEST)
    report = launch_dir / "out" / "report.xml"

    code, out, err = rosl.run(
        "launch_test", str(path), "-v", "--junit-xml", str(report), "--package-name", "my_pkg",
        timeout=180,
    )  # fmt: skip

    assert code == 1, f"{out}\n{err}"  # test_fails_for_beta fails in the beta run only
    assert "[DEBUG] [launch_test]: Running integration test my_pkg[word=alpha, count=1]" in out
    assert "[DEBUG] [launch_test]: Wrote the JUnit report to" in out
    root = ET.parse(report).getroot()
    assert root.tag == "testsuites"
    assert root.get("name") == "my_pkg.test_tools"
    assert (root.get("tests"), root.get("failures"), root.get("errors")) == ("6", "1", "0")
    suites = {s.get("name"): s for s in root}
    assert set(suites) == {
        "my_pkg.test_tools.launch_tests[word=alpha, count=1]",
        "my_pkg.test_tools.launch_tests[word=beta, count=2]",
    }
    beta = suites["my_pkg.test_tools.launch_tests[word=beta, count=2]"]
    cases = {c.get("name"): c for c in beta.iter("testcase")}
    assert set(cases) == {"test_launch_process", "test_wait_for_output_then_stop",
                          "test_fails_for_beta"}  # fmt: skip
    assert all(c.get("classname") == "TestTools" for c in cases.values())
    failure = cases["test_fails_for_beta"].find("failure")
    assert failure is not None
    assert "AssertionError" in (failure.get("message") or "")
    assert cases["test_launch_process"].find("failure") is None


def test_pytest_runs_each_value_of_a_parametrized_launch_test(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(launch_dir, "test_tools.py", TOOLS_TEST)
    command = [sys.executable, "-m", "pytest", "-s", "-p", "no:cacheprovider", str(path)]
    output = Output(rosl.processes.start(command, cwd=launch_dir))
    rosl.watched.append(output)

    code = output.finish(180)

    text = output.both()
    assert code == 1, text
    assert "1 failed: TestTools.test_fails_for_beta" in text, text
    assert text.count("test_launch_process (test_tools.TestTools.test_launch_process) ... ok") == 2
    assert_all_gone(output.pids())


def test_junit_report_of_a_launch_that_ended_early_holds_the_problem(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "test_early.py",
        """
        import unittest
        import launch
        import launch.actions
        import launch_testing.actions
        def generate_test_description():
            return launch.LaunchDescription([
                launch.actions.ExecuteProcess(cmd=["true"]),
                launch_testing.actions.ReadyToTest(),
            ])
        class TestWaits(unittest.TestCase):
            def test_waits(self, proc_output):
                proc_output.assertWaitFor("never", timeout=30)
        """,
    )
    report = launch_dir / "early.xml"

    code, out, err = rosl.run("launch_test", str(path), "--junit-xml", str(report))

    assert code == 1, f"{out}\n{err}"
    root = ET.parse(report).getroot()
    errors = [e.get("message") for e in root.iter("error")]
    assert errors == ["Processes under test stopped before tests completed"], ET.tostring(root)


def test_an_unwritable_junit_report_is_one_line(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "test_quick.py",
        """
        import unittest
        import launch
        import launch_testing.actions
        def generate_test_description():
            return launch.LaunchDescription([launch_testing.actions.ReadyToTest()])
        class TestNothing(unittest.TestCase):
            def test_nothing(self):
                pass
        """,
    )
    blocker = launch_dir / "a_file"
    blocker.write_text("")

    code, out, err = rosl.run("launch_test", str(path), "--junit-xml", str(blocker / "r.xml"))

    assert code == 1, f"{out}\n{err}"
    assert "Traceback" not in err, err  # unittest's report, then the one line
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"cannot write the JUnit report {blocker}/r.xml: "), err


def test_expect_output_matches_lines_and_text_as_launch_testing_does() -> None:
    text = "\x1b[32mstart\x1b[0m\nhello 1\nhello 2\nend\n"

    assert expect_output(text, expected_lines=["hello 1", re.compile(r"hello \d")])
    assert expect_output(text, expected_lines=["start", "hello 1"], strict=True)
    assert not expect_output(text, expected_lines=["start", "hello 2"], strict=True)
    assert not expect_output(text, expected_lines=["hello 2", "hello 1"])
    assert expect_output(lines=["a", "b"], expected_text="a\nb")
    assert expect_output(text, expected_text=re.compile(r"hello 1\nhello 2"))
    assert expect_output(text, expected_text="start\nhello")
    assert not expect_output(text, expected_text="start\nhello", strip_ansi_escape_sequences=False)
    assert build_line_match("x", strict=True)(["x1", "x2"]) == (0, 2)
    with pytest.raises(ValueError, match="Either lines or text"):
        expect_output(expected_lines=["x"])
    with pytest.raises(ValueError, match="Either expected lines or text"):
        expect_output("x", expected_lines=["x"], expected_text="x")


def test_basic_output_filter_and_expected_output_files(tmp_path: Path) -> None:
    drop = basic_output_filter(filtered_patterns=[r"noise \d+"])

    assert drop("pid 12\nkept\nnoise 3\nrc 0\nalso kept\n") == "kept\nalso kept\n"
    assert basic_output_filter(filtered_prefixes=["x"])("pid 1\nx 2\n") == "pid 1\n"
    (tmp_path / "lines.txt").write_text("one\ntwo\n")
    (tmp_path / "patterns.regex").write_text("on.\ntw\\w\n")
    assert expected_output_from_file(str(tmp_path / "lines")) == ["one", "two"]
    patterns = expected_output_from_file(str(tmp_path / "patterns"))
    assert expect_output("one\ntwo", expected_lines=patterns, strict=True)
    with pytest.raises(RuntimeError, match="could not find output check file"):
        expected_output_from_file(str(tmp_path / "missing"))


@pytest.mark.parametrize("suffix", ["xml", "py"])
def test_respawn_stops_after_respawn_max_retries(rosl: Rosl, launch_dir: Path, suffix: str) -> None:
    source = (
        '<launch>\n  <executable cmd="echo once more" output="screen" respawn="true"'
        ' respawn_delay="0.1" respawn_max_retries="2"/>\n</launch>\n'
        if suffix == "xml"
        else """
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess
        def generate_launch_description():
            return LaunchDescription([ExecuteProcess(
                cmd=["echo", "once more"], output="screen", respawn=True, respawn_delay=0.1,
                respawn_max_retries=2, cached_output=True)])
        """
    )
    path = write_launch(launch_dir, f"respawn.launch.{suffix}", source)

    code, out, err = rosl.run("launch", str(path))

    assert code == 0, f"{out}\n{err}"
    assert out.count("[echo-1] once more") == 3, out  # the first run and two retries


def test_file_content_path_substitution_and_launch_log_dir(
    rosl: Rosl, launch_dir: Path, log_dir: Path
) -> None:
    (launch_dir / "config").mkdir()
    (launch_dir / "config" / "motd.txt").write_text("hello from a file")
    path = write_launch(
        launch_dir,
        "content.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import LogInfo
        from launch.substitutions import (FileContent, LaunchLogDir, PathSubstitution,
                                          ThisLaunchFileDir)
        def generate_launch_description():
            motd = PathSubstitution(ThisLaunchFileDir()) / "config" / "motd.txt"
            return LaunchDescription([
                LogInfo(msg=["python: ", FileContent(motd)]),
                LogInfo(msg=["log dir: ", LaunchLogDir()]),
            ])
        """,
    )
    xml = write_launch(
        launch_dir,
        "content.launch.xml",
        '<launch>\n  <log message="xml: $(file-content $(dirname)/config/motd.txt)"/>\n</launch>\n',
    )

    code, out, err = rosl.run("launch", str(path))
    xml_code, xml_out, xml_err = rosl.run("launch", str(xml))

    assert code == 0, f"{out}\n{err}"
    assert "[INFO] [launch.user]: python: hello from a file" in out, out
    logged = re.search(r"\[launch\.user\]: log dir: (\S+)", out)
    assert logged is not None, out
    assert logged.group(1).startswith(str(log_dir)), out
    assert xml_code == 0, f"{xml_out}\n{xml_err}"
    assert "[INFO] [launch.user]: xml: hello from a file" in xml_out, xml_out


def test_a_missing_file_content_is_one_line_at_its_tag(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "missing.launch.xml",
        '<launch>\n  <log message="$(file-content /no/such/file.txt)"/>\n</launch>\n',
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err) == (
        f"{path}:2: cannot read file /no/such/file.txt: No such file or directory"
    )


SERVICE = """
import sys
import threading

import rosl.compat

rosl.compat.install()
import launch
from launch.actions import DeclareLaunchArgument, ExecuteProcess, LogInfo
from launch.substitutions import LaunchConfiguration

service = launch.LaunchService(argv=sys.argv[1:])
service.include_launch_description(launch.LaunchDescription([
    DeclareLaunchArgument("word", default_value="unset"),
    LogInfo(msg=["word is ", LaunchConfiguration("word")]),
    ExecuteProcess(cmd=["echo", "from the service"], output="screen"),
]))
print("first run:", service.run(), flush=True)
second = launch.LaunchService()
second.include_launch_description(launch.LaunchDescription([ExecuteProcess(cmd=["sleep", "60"])]))
threading.Timer(1.0, second.shutdown).start()
print("second run:", second.run(), flush=True)
"""


def test_launch_service_runs_a_description_from_a_program(rosl: Rosl, launch_dir: Path) -> None:
    script = write_launch(launch_dir, "service.py", SERVICE)
    output = Output(rosl.processes.start([sys.executable, str(script), "word:=hi"]))
    rosl.watched.append(output)

    code = output.finish(60)

    out = output.text()
    assert code == 0, output.both()
    assert "[INFO] [launch.user]: word is hi" in out, out
    assert "[echo-1] from the service" in out, out
    assert "first run: 0" in out, out
    assert re.search(r"\[sleep-1\]: process has died \[pid \d+, exit code -2", out), out
    assert "second run: 0" in out, out
    assert_all_gone(output.pids())


@pytest.mark.parametrize(
    ("body", "line", "message"),
    [
        (
            """
            from launch import LaunchDescription
            from launch.actions import OpaqueFunction
            def setup(context):
                return [1 / 0]
            def generate_launch_description():
                return LaunchDescription([OpaqueFunction(function=setup)])
            """,
            4,
            "ZeroDivisionError: division by zero",
        ),
        (
            """
            from launch import LaunchDescription
            from launch.actions import ExecuteProcess, RegisterEventHandler
            from launch.event_handlers import OnProcessExit
            def on_exit(event, context):
                return {}["missing"]
            def generate_launch_description():
                p = ExecuteProcess(cmd=["true"])
                return LaunchDescription([
                    p, RegisterEventHandler(OnProcessExit(target_action=p, on_exit=on_exit))])
            """,
            5,
            "KeyError: 'missing'",
        ),
    ],
    ids=["opaque_function", "event_handler"],
)
def test_an_exception_in_the_launch_files_own_function_is_one_line_at_its_line(
    rosl: Rosl, launch_dir: Path, body: str, line: int, message: str
) -> None:
    path = write_launch(launch_dir, "raises.launch.py", body)

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err) == f"{path}:{line}: {message}"
