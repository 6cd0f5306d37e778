"""The launch API in small launch files: groups, namespaces, parameters, environment, timers,
includes, conditions, event handlers and shutdown, each run by a real ``rosl launch``."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import pytest

from tests.conftest import wait_until
from tests.launch.support import PYTHON, assert_all_gone, one_error_line, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Output, Rosl

PRINT_AND_EXIT = "import sys; print(' '.join(sys.argv[1:]), flush=True)"


def node_list(rosl: Rosl) -> list[str]:
    """``rosl node list`` on the test's domain."""
    code, out, err = rosl.run("node", "list")
    assert code == 0, err
    return out.splitlines()


def index_of(launch: Output, pattern: str) -> int:
    """The index of the first stdout line matching ``pattern``."""
    for index, line in enumerate(launch.lines()):
        if re.search(pattern, line):
            return index
    raise AssertionError(f"no line matches {pattern!r}\n{launch.both()}")


def stop(launch: Output) -> None:
    """Ctrl-C the launcher; it must exit 0 and leave none of its processes running."""
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    assert_all_gone(pids)


def test_group_with_push_ros_namespace_puts_its_nodes_under_the_namespace(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "group.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import GroupAction
        from launch_ros.actions import Node, PushRosNamespace


        def generate_launch_description():
            return LaunchDescription([
                GroupAction([
                    PushRosNamespace("ns"),
                    Node(package="tutorial_pkg", executable="my_subscriber", name="inside"),
                ]),
                Node(package="tutorial_pkg", executable="my_subscriber", name="outside"),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.wait_for(r"process started with pid", count=2), launch.both()
    assert wait_until(lambda: {"/ns/inside", "/outside"} <= set(node_list(rosl)), timeout=60.0), (
        f"{node_list(rosl)}\n{launch.both()}"
    )
    assert "/inside" not in node_list(rosl)
    stop(launch)


def test_set_parameter_gives_the_parameter_to_every_node_after_it(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "set_parameter.launch.py",
        """
        from launch import LaunchDescription
        from launch_ros.actions import Node, SetParameter


        def generate_launch_description():
            return LaunchDescription([
                SetParameter(name="timer_period_s", value=0.7),
                Node(package="tutorial_pkg", executable="timer_node", name="first_timer",
                     output="screen"),
                Node(package="tutorial_pkg", executable="timer_node", name="second_timer",
                     output="screen"),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.wait_for(r"\[first_timer\]: Timer period: 0\.7 s$"), launch.both()
    assert launch.wait_for(r"\[second_timer\]: Timer period: 0\.7 s$"), launch.both()
    stop(launch)


def test_set_environment_variable_reaches_the_processes_started_after_it(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "environment.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess, SetEnvironmentVariable

        SHOW = "import os; print('ROSL_TEST_VALUE=' + os.environ.get('ROSL_TEST_VALUE', '<unset>'))"


        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd=[{PYTHON!r}, "-c", SHOW], name="before", output="screen"),
                SetEnvironmentVariable("ROSL_TEST_VALUE", "forty-two"),
                ExecuteProcess(cmd=[{PYTHON!r}, "-c", SHOW], name="after", output="screen"),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.finish() == 0, launch.both()
    assert "[after-2] ROSL_TEST_VALUE=forty-two" in launch.lines(), launch.both()
    assert "[before-1] ROSL_TEST_VALUE=<unset>" in launch.lines(), launch.both()
    assert_all_gone(launch.pids())


def test_timer_action_starts_its_process_only_after_the_period(
    rosl: Rosl, launch_dir: Path, log_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "timer.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess, LogInfo, TimerAction


        def generate_launch_description():
            return LaunchDescription([
                LogInfo(msg="timer armed"),
                TimerAction(period=1.0, actions=[
                    ExecuteProcess(cmd=[{PYTHON!r}, "-c", {PRINT_AND_EXIT!r}, "late"],
                                   name="late", output="screen"),
                ]),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.finish() == 0, launch.both()
    assert "[late-1] late" in launch.lines(), launch.both()
    assert index_of(launch, r"\[launch\.user\]: timer armed") < index_of(
        launch, r"\[late-1\]: process started"
    )
    # launch.log stamps every line: the process must not start before its period
    stamps = {}
    for line in (launch.log_folder() / "launch.log").read_text().splitlines():
        stamp, _, text = line.partition(" ")
        if "timer armed" in text:
            stamps["armed"] = float(stamp)
        elif "[late-1]: process started" in text:
            stamps["late"] = float(stamp)
    assert stamps["late"] - stamps["armed"] >= 0.99, stamps
    assert_all_gone(launch.pids())


def test_log_info_prints_a_launch_user_line_with_substitutions(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "log_info.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument, LogInfo
        from launch.substitutions import LaunchConfiguration


        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("who", default_value="world"),
                LogInfo(msg=["hello ", LaunchConfiguration("who")]),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(path), "who:=rosl")

    assert code == 0, err
    assert "[INFO] [launch.user]: hello rosl" in out.splitlines()


def test_include_passes_launch_arguments_to_the_included_python_file(
    rosl: Rosl, launch_dir: Path
) -> None:
    write_launch(
        launch_dir,
        "child.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument, ExecuteProcess, LogInfo
        from launch.substitutions import LaunchConfiguration


        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("who", default_value="nobody"),
                LogInfo(msg=["child says ", LaunchConfiguration("who")]),
                ExecuteProcess(cmd=[{PYTHON!r}, "-c", {PRINT_AND_EXIT!r},
                                    LaunchConfiguration("who")],
                               name="child_process", output="screen"),
            ])
        """,
    )
    parent = write_launch(
        launch_dir,
        "parent.launch.py",
        """
        import os

        from launch import LaunchDescription
        from launch.actions import IncludeLaunchDescription
        from launch.launch_description_sources import PythonLaunchDescriptionSource
        from launch.substitutions import PathJoinSubstitution


        def generate_launch_description():
            here = os.path.dirname(__file__)
            return LaunchDescription([
                IncludeLaunchDescription(
                    PythonLaunchDescriptionSource(PathJoinSubstitution([here, "child.launch.py"])),
                    launch_arguments={"who": "the parent"}.items(),
                ),
            ])
        """,
    )

    launch = rosl.start("launch", str(parent))

    assert launch.finish() == 0, launch.both()
    assert "[INFO] [launch.user]: child says the parent" in launch.lines(), launch.both()
    assert "[child_process-1] the parent" in launch.lines(), launch.both()
    assert_all_gone(launch.pids())


@pytest.mark.parametrize(
    ("flag", "ran", "skipped"), [("true", "if", "unless"), ("0", "unless", "if")]
)
def test_if_and_unless_conditions_choose_which_actions_run(
    rosl: Rosl, launch_dir: Path, flag: str, ran: str, skipped: str
) -> None:
    path = write_launch(
        launch_dir,
        "conditions.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument, LogInfo
        from launch.conditions import IfCondition, UnlessCondition
        from launch.substitutions import LaunchConfiguration


        def generate_launch_description():
            flag = LaunchConfiguration("flag")
            return LaunchDescription([
                DeclareLaunchArgument("flag"),
                LogInfo(msg="if ran", condition=IfCondition(flag)),
                LogInfo(msg="unless ran", condition=UnlessCondition(flag)),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(path), f"flag:={flag}")

    assert code == 0, err
    assert f"[INFO] [launch.user]: {ran} ran" in out.splitlines()
    assert f"{skipped} ran" not in out


def test_on_process_start_and_on_process_exit_handlers_run_their_actions(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "events.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess, LogInfo, RegisterEventHandler
        from launch.event_handlers import OnProcessExit, OnProcessStart

        first = ExecuteProcess(cmd=[{PYTHON!r}, "-c", "import sys; sys.exit(4)"], name="first")
        second = ExecuteProcess(cmd=[{PYTHON!r}, "-c", {PRINT_AND_EXIT!r}, "second ran"],
                                name="second", output="screen")


        def generate_launch_description():
            return LaunchDescription([
                RegisterEventHandler(OnProcessStart(
                    target_action=first, on_start=[LogInfo(msg="first is up")])),
                RegisterEventHandler(OnProcessExit(
                    target_action=first,
                    on_exit=lambda event, context: [
                        LogInfo(msg=f"first exited with {{event.returncode}}"), second
                    ],
                )),
                first,
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    launch.finish()
    assert "[INFO] [launch.user]: first is up" in launch.lines(), launch.both()
    assert "[INFO] [launch.user]: first exited with 4" in launch.lines(), launch.both()
    assert "[second-2] second ran" in launch.lines(), launch.both()
    assert index_of(launch, r"\[first-1\]: process started") < index_of(launch, r"first is up")
    assert index_of(launch, r"\[first-1\]: process has died") < index_of(
        launch, r"\[second-2\]: process started"
    )
    assert_all_gone(launch.pids())


def test_emit_shutdown_on_a_process_exit_ends_the_whole_launch(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "shutdown.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import EmitEvent, ExecuteProcess, RegisterEventHandler
        from launch.event_handlers import OnProcessExit
        from launch.events import Shutdown

        quick = ExecuteProcess(cmd=[{PYTHON!r}, "-c", "pass"], name="quick")


        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd=[{PYTHON!r}, "-c", "import time; time.sleep(60)"],
                               name="sleeper"),
                quick,
                RegisterEventHandler(OnProcessExit(
                    target_action=quick, on_exit=[EmitEvent(event=Shutdown(reason="done"))])),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    # nobody interrupts it: the Shutdown event alone must end the launch
    assert launch.finish(timeout=30.0) == 0, launch.both()
    assert launch.matching(r"^\[INFO\] \[quick-2\]: process has finished cleanly")
    assert launch.matching(r"\[sleeper-1\]: process has (finished|died)"), launch.both()
    assert len(launch.pids()) == 2
    assert_all_gone(launch.pids())


def test_output_screen_shows_both_streams_prefixed(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "screen.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess

        TALK = "import sys; print('to stdout'); print('to stderr', file=sys.stderr)"


        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd=[{PYTHON!r}, "-c", TALK], name="talk", output="screen"),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.finish() == 0, launch.both()
    assert "[talk-1] to stdout" in launch.lines()
    assert "[talk-1] to stderr" in launch.lines()
    assert_all_gone(launch.pids())


def test_default_output_log_keeps_stdout_in_launch_log_and_shows_stderr(
    rosl: Rosl, launch_dir: Path, log_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "log.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess

        TALK = "import sys; print('to stdout'); print('to stderr', file=sys.stderr)"


        def generate_launch_description():
            return LaunchDescription([ExecuteProcess(cmd=[{PYTHON!r}, "-c", TALK], name="talk")])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.finish() == 0, launch.both()
    assert "to stdout" not in launch.text("out") + launch.text("err")
    assert "[talk-1] to stderr" in launch.lines(), launch.both()
    folder = launch.log_folder()
    assert folder.parent == log_dir
    logged = (folder / "launch.log").read_text()
    assert re.search(r"^\d+\.\d+ \[talk-1\] to stdout$", logged, re.MULTILINE), logged
    assert_all_gone(launch.pids())


def test_respawn_restarts_a_process_that_exits_after_the_delay(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "respawn.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess


        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd=[{PYTHON!r}, "-c", "print('alive', flush=True)"],
                               name="flaky", output="screen", respawn=True, respawn_delay=0.3),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.wait_for(r"\[flaky-1\]: process started", count=3), launch.both()
    starts = launch.started()
    assert list(starts) == ["flaky-1"]
    pids = starts["flaky-1"]
    assert len(set(pids)) == len(pids), "each respawn is a new process"
    assert launch.matching(r"^\[INFO\] \[flaky-1\]: process has finished cleanly")
    stop(launch)


def test_a_parameter_from_a_launch_configuration_is_typed_by_yaml_rules(
    rosl: Rosl, launch_dir: Path
) -> None:
    # launch_ros evaluates substitutions in parameter dicts "according to yaml rules":
    # period:=0.9 gives the double 0.9 (the use_sim_time:=true idiom relies on it)
    path = write_launch(
        launch_dir,
        "typed_parameter.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument
        from launch.substitutions import LaunchConfiguration
        from launch_ros.actions import Node


        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("period", default_value="0.4"),
                Node(package="tutorial_pkg", executable="timer_node", output="screen",
                     parameters=[{"timer_period_s": LaunchConfiguration("period")}]),
            ])
        """,
    )

    launch = rosl.start("launch", str(path), "period:=0.9")

    assert launch.wait_for(r"\[timer_node\]: Timer period: 0\.9 s$", timeout=30.0), launch.both()
    stop(launch)


def test_node_parameters_may_come_from_a_yaml_parameter_file(rosl: Rosl, launch_dir: Path) -> None:
    params = launch_dir / "timers.yaml"
    params.write_text(
        "/**:\n  ros__parameters:\n    timer_period_s: 0.3\n"
        "/slow_timer:\n  ros__parameters:\n    timer_period_s: 0.6\n"
    )
    path = write_launch(
        launch_dir,
        "param_file.launch.py",
        f"""
        from launch import LaunchDescription
        from launch_ros.actions import Node


        def generate_launch_description():
            return LaunchDescription([
                Node(package="tutorial_pkg", executable="timer_node", name="fast_timer",
                     parameters=[{str(params)!r}], output="screen"),
                Node(package="tutorial_pkg", executable="timer_node", name="slow_timer",
                     parameters=[{str(params)!r}], output="screen"),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.wait_for(r"\[fast_timer\]: Timer period: 0\.3 s$"), launch.both()
    assert launch.wait_for(r"\[slow_timer\]: Timer period: 0\.6 s$"), launch.both()
    stop(launch)


def test_a_missing_parameter_file_is_one_error_line_and_leaves_nothing_running(
    rosl: Rosl, launch_dir: Path
) -> None:
    missing = launch_dir / "missing.yaml"
    path = write_launch(
        launch_dir,
        "missing_param_file.launch.py",
        f"""
        from launch import LaunchDescription
        from launch_ros.actions import Node


        def generate_launch_description():
            return LaunchDescription([
                Node(package="tutorial_pkg", executable="my_subscriber"),
                Node(package="tutorial_pkg", executable="timer_node",
                     parameters=[{str(missing)!r}]),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.finish() == 1, launch.both()
    assert one_error_line(launch.text("err")).startswith(  # the line of its Node(...)
        f"{path}:8: parameter file {missing} "
    ), launch.both()
    if launch.pids():
        assert_all_gone(launch.pids())
