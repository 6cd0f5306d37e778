"""The Python launch API as real launch files use it: ``import launch`` / ``import launch_ros``
and attribute access, ``ament_index_python``, substitutions, environment actions, event
handlers, and real launch files of ros2/demos written for Python nodes; what rosl cannot run
(components, names it lacks) is one line and exit 1.

The packages live in tests/launch/python_api (see its README), put on ROSL_PACKAGE_PATH.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
from typing import TYPE_CHECKING

import pytest

from tests.conftest import REPO
from tests.launch.support import (
    EXAMPLES,
    PYTHON,
    assert_all_gone,
    one_error_line,
    write_launch,
)

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Output, Rosl

PACKAGES = REPO / "tests" / "launch" / "python_api"
CHECK = PACKAGES / "python_api_check"
TUTORIAL = EXAMPLES / "tutorial_pkg"
ENTRY = [PYTHON, "-P", "-m", "rosl.pkg.entry"]


@pytest.fixture(autouse=True)
def packages(log_dir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """This folder's packages on the package path, before rosl's examples."""
    monkeypatch.setenv("ROSL_PACKAGE_PATH", f"{PACKAGES}{os.pathsep}{EXAMPLES}")


def printed(rosl: Rosl, *args: str) -> list[str]:
    """``rosl launch --print ARGS``: it must succeed; its stdout lines."""
    code, out, err = rosl.run("launch", "--print", *args)
    assert code == 0, f"{out}\n{err}"
    return out.splitlines()


def commands(lines: list[str]) -> dict[str, list[str]]:
    """``[label] command`` lines of ``--print`` as label -> argv."""
    found = {}
    for line in lines:
        if line.startswith("[") and "] " in line:
            label, _, command = line[1:].partition("] ")
            found[label] = shlex.split(command)
    return found


def timer_node(*ros_args: str) -> list[str]:
    """The argv of tutorial_pkg's timer_node with ``ros_args``."""
    argv = [*ENTRY, str(TUTORIAL), "tutorial_pkg.timer_node:main", "timer_node"]
    return [*argv, "--ros-args", *ros_args] if ros_args else argv


def stop(launch: Output) -> None:
    """Ctrl-C the launcher: exit 0, none of its processes left."""
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    assert_all_gone(pids)


def index_of(launch: Output, text: str) -> int:
    """The index of the first stdout line containing ``text``."""
    for index, line in enumerate(launch.lines()):
        if text in line:
            return index
    raise AssertionError(f"no line contains {text!r}\n{launch.both()}")


# --- what --print shows ---------------------------------------------------------------------


def test_print_resolves_the_api_reached_through_import_launch_and_import_launch_ros(
    rosl: Rosl,
) -> None:
    lines = printed(rosl, "python_api_check", "api_print.launch.py")

    assert commands(lines) == {
        "timer_node-1": timer_node("-r", "__node:=fast_timer", "-p", "timer_period_s:=0.25"),
        "finder-2": [shutil.which("sh"), "-c", "exit 0"],
        "timer_node-3": timer_node(),  # ExecutableInPackage: the entry's argv, named after it
        "paths-4": ["cat", str(CHECK / "config" / "timer.yaml")],
        "prefixes-5": ["echo", str(CHECK), str(CHECK), str(CHECK)],
        "texts-6": ["echo", "fallback+text", str(CHECK / "launch")],
        "piped-7": ["/bin/sh", "-c", "echo fast | tr a-z A-Z"],
        "opaque-8": ["echo", "opaque saw fast"],
    }, "\n".join(lines)
    assert "    node: fast_timer (package tutorial_pkg, namespace /)" in lines
    assert "    param: timer_period_s = 0.25" in lines


def test_print_follows_the_conditions_when_the_argument_changes(rosl: Rosl) -> None:
    lines = printed(rosl, "python_api_check", "api_print.launch.py", "mode:=slow")

    found = commands(lines)
    # LaunchConfigurationEquals('mode', 'fast') is now false, the PythonExpression true
    params = str(CHECK / "config" / "timer.yaml")  # ParameterFile(get_package_share_directory...)
    assert found["timer_node-1"] == timer_node("-r", "__node:=slow_timer", "--params-file", params)
    assert "fast_timer" not in "\n".join(lines)
    assert found["piped-7"] == ["/bin/sh", "-c", "echo slow | tr a-z A-Z"]
    assert found["opaque-8"] == ["echo", "opaque saw slow"]


def test_print_of_real_topic_monitor_files_shows_their_publishers(rosl: Rosl) -> None:
    fragmentation = commands(printed(rosl, "topic_monitor", "fragmentation_demo.launch.py"))
    reliability = commands(printed(rosl, "topic_monitor", "reliability_demo.launch.py"))

    publisher = [*ENTRY, str(PACKAGES / "topic_monitor"),
                 "topic_monitor.scripts.data_publisher:main", "data_publisher"]  # fmt: skip
    assert fragmentation == {
        f"data_publisher-{index}": [*publisher, name, "--payload-size", size, "--period", "4"]
        for index, (name, size) in enumerate(
            [("small", "1"), ("medium", "50000"), ("large", "100000"), ("xlarge", "150000")],
            start=1,
        )
    }
    assert reliability == {
        "data_publisher-1": [*publisher, "sensor", "--best-effort"],
        "data_publisher-2": [*publisher, "critical"],
    }


# --- running --------------------------------------------------------------------------------


def test_a_run_sets_the_environment_runs_the_handlers_and_ends_on_a_shutdown_event(
    rosl: Rosl,
) -> None:
    launch = rosl.start("launch", "python_api_check", "api_run.launch.py", "word:=loud")

    # nobody interrupts it: the Shutdown emitted when share_reader exits ends the sleeper too
    assert launch.finish(timeout=60.0) == 0, launch.both()
    lines = launch.lines()
    user = [
        line.removeprefix("[INFO] [launch.user]: ") for line in lines if "[launch.user]" in line
    ]
    assert user[:2] == [f"share {CHECK}", "no_such_package is not installed"], launch.both()
    assert sorted(user[2:]) == sorted(
        [
            "show_env started",
            "show_env exited with 0",
            "shell said LOUD",  # OnProcessIO: the line, as bytes, given to on_stdout
            "opaque saw word=loud and loud",
            "one of clean_env and share_reader exited",
            "one of clean_env and share_reader exited",
            "the first of clean_env and share_reader exited",  # handle_once
        ]
    ), launch.both()
    # SetEnvironmentVariable, AppendEnvironmentVariable (appended, ';', prepended), cwd from
    # ThisLaunchFileDir, additional_env; env= starts from a clean environment
    assert (
        f"[show_env-2] cwd={CHECK / 'launch'} API_PATH=first{os.pathsep}middle;last "
        "API_SET=set EXTRA=more"
    ) in lines, launch.both()
    assert "[shell-3] LOUD" in lines, launch.both()
    assert "[clean_env-4] clean API_SET=unset ONLY=this" in lines, launch.both()
    # ament_index_python inside a node's own process
    assert (f"[share_reader-5] share_reader: share={CHECK} prefix={CHECK}") in lines
    assert "[share_reader-5] share_reader: config found=True same=True" in lines
    missing = [line for line in lines if "missing package:" in line]
    assert missing, launch.both()
    assert "package 'no_such_package' not found" in missing[0]
    # the handlers ran in the order of the events they answer
    assert index_of(launch, "[show_env-2]: process started") < index_of(launch, "show_env started")
    assert index_of(launch, "[show_env-2]: process has finished") < index_of(
        launch, "[shell-3]: process started"
    )
    assert index_of(launch, "[shell-3]: process has finished") < index_of(
        launch, "[clean_env-4]: process started"
    )
    assert index_of(launch, "[share_reader-5]: process has finished") < index_of(
        launch, "[sleeper-1]: process has"
    )
    assert len(launch.pids()) == 5
    assert_all_gone(launch.pids())


def test_real_add_two_ints_launch_file_ends_when_its_client_exits(rosl: Rosl) -> None:
    launch = rosl.start("launch", "demo_nodes_py", "add_two_ints.launch.py")

    assert launch.finish(timeout=60.0) == 0, launch.both()
    assert launch.matching(
        r"^\[add_two_ints_client-2\] \[INFO\] \[\d+\.\d+\] \[add_two_ints_client\]: "
        r"Result of add_two_ints: for 2 \+ 3 = 5$"
    ), launch.both()
    assert launch.matching(r"\[add_two_ints_server\]: Incoming request a: 2 b: 3$")
    # the server serves forever: only the Shutdown event of the OnProcessExit handler stops it
    assert index_of(launch, "[add_two_ints_client-2]: process has finished cleanly") < index_of(
        launch, "[add_two_ints_server-1]: process has"
    )
    assert_all_gone(launch.pids())


def test_real_talker_listener_launch_file_runs_the_python_nodes(rosl: Rosl) -> None:
    launch = rosl.start("launch", "demo_nodes_py", "talker_listener.launch.py")

    assert launch.wait_for(r"^\[listener-2\] .*\[listener\]: I heard: \[Hello World: \d+\]$"), (
        launch.both()
    )
    assert launch.matching(r'^\[talker-1\] .*\[talker\]: Publishing: "Hello World: 0"$')
    stop(launch)


def test_real_depth_demo_starts_the_executable_found_in_its_package(rosl: Rosl) -> None:
    launch = rosl.start("launch", "topic_monitor", "depth_demo.launch.py")

    expected = {
        1: "small_depth_1_data': #1 (0-byte payload, depth 1, reliable)",
        2: "small_depth_50_data': #1 (0-byte payload, depth 50, reliable)",
        3: "large_depth_1_data': #1 (100000-byte payload, depth 1, reliable)",
        4: "large_depth_50_data': #1 (100000-byte payload, depth 50, reliable)",
    }
    for index, text in expected.items():
        assert launch.wait_for(
            rf"^\[data_publisher-{index}\] .*Publishing on '{re.escape(text)}$"
        ), launch.both()
    assert sorted(launch.started()) == [f"data_publisher-{i}" for i in expected]
    stop(launch)


# --- what rosl cannot run: one line, exit 1, nothing started ----------------------------------


@pytest.mark.parametrize(
    ("package", "file_name", "line", "message"),
    [
        (
            "composition",
            "composition_demo.launch.py",
            10,
            "'launch_ros.actions.ComposableNodeContainer' is not supported: it runs C++ "
            "components, which rosl cannot: composition::Talker, composition::Listener",
        ),
    ],
)
def test_real_component_launch_files_are_refused_in_one_line(
    rosl: Rosl, package: str, file_name: str, line: int, message: str
) -> None:
    code, out, err = rosl.run("launch", package, file_name)

    assert code == 1, f"{out}\n{err}"
    assert "process started" not in out
    path = PACKAGES / package / "launch" / file_name
    assert one_error_line(err).startswith(f"{path}:{line}: {message}"), err


@pytest.mark.parametrize(
    ("source", "line", "message"),
    [
        (
            "launch_ros.actions.LoadComposableNodes(target_container='c', "
            "composable_node_descriptions=[launch_ros.descriptions.ComposableNode("
            "package='image_tools', plugin='image_tools::Cam2Image')])",
            6,
            "'launch_ros.actions.LoadComposableNodes' is not supported: it runs C++ components, "
            "which rosl cannot: image_tools::Cam2Image",
        ),
        (
            "launch.actions.ExecuteLocal(process_description=None)",
            6,
            "'launch.actions.ExecuteLocal' is not supported by rosl",
        ),
        (
            "launch_ros.actions.Node(package='tutorial_pkg', executable='timer_node', "
            "parameters=[42])",
            6,
            "parameters of timer_node must be dicts or YAML file paths, not int",
        ),
        (
            "launch.actions.LogInfo(msg=get_package_share_directory('no_such_package'))",
            6,
            "PackageNotFoundError: package 'no_such_package' not found",
        ),
    ],
)
def test_what_rosl_lacks_is_one_line_naming_the_file_line_and_the_name(
    rosl: Rosl, launch_dir: Path, source: str, line: int, message: str
) -> None:
    path = write_launch(
        launch_dir,
        "lacking.launch.py",
        f"""
        import launch
        import launch_ros
        from ament_index_python.packages import get_package_share_directory
        def generate_launch_description():
            return launch.LaunchDescription([
                {source},
            ])
        """,
    )

    code, out, err = rosl.run("launch", "--print", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err).startswith(f"{path}:{line}: {message}"), err


UNSET_AND_ON_SHUTDOWN = """
import sys

import launch


def generate_launch_description():
    def farewell(event, context):
        return launch.actions.LogInfo(msg=f"shutting down: {event.reason}")

    show = "import os; print('ROSL_TEST_A=' + os.environ.get('ROSL_TEST_A', '<unset>'))"
    return launch.LaunchDescription([
        launch.actions.SetEnvironmentVariable("ROSL_TEST_A", "set"),
        launch.actions.UnsetEnvironmentVariable("ROSL_TEST_A"),
        launch.actions.RegisterEventHandler(
            launch.event_handlers.OnShutdown(on_shutdown=farewell)
        ),
        launch.actions.ExecuteProcess(cmd=[sys.executable, "-c", show], output="screen"),
    ])
"""


def test_unset_environment_variable_and_on_shutdown_work_as_in_launch(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "unset.launch.py", UNSET_AND_ON_SHUTDOWN)
    code, out, err = rosl.run("launch", str(path))
    assert code == 0, f"{out}\n{err}"
    text = out + err
    assert "ROSL_TEST_A=<unset>" in text, text
    assert "shutting down: all processes have finished" in text, text


HANDLER_AFTER = """
import sys

import launch


def generate_launch_description():
    worker = launch.actions.ExecuteProcess(
        cmd=["echo", "hello_world"], shell=True, output="screen"
    )
    return launch.LaunchDescription([
        worker,  # registered after its target, as the event-handler tutorial writes it
        launch.actions.RegisterEventHandler(
            launch.event_handlers.OnProcessStart(
                target_action=worker, on_start=[launch.actions.LogInfo(msg="worker is up")]
            )
        ),
    ])
"""


def test_a_handler_registered_after_its_action_sees_it_start_and_a_shell_is_named_by_its_command(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "after.launch.py", HANDLER_AFTER)
    code, out, err = rosl.run("launch", str(path))
    assert code == 0, f"{out}\n{err}"
    text = out + err
    assert "[launch.user]: worker is up" in text, text
    assert "[echo-1] hello_world" in text, text  # echo-1, not sh-1


def test_a_bad_timer_period_is_one_line(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "timer.launch.xml",
        """
        <launch>
          <timer period="abc"><log message="never"/></timer>
        </launch>
        """,
    )
    code, out, err = rosl.run("launch", str(path))
    assert code == 1, f"{out}\n{err}"
    line = one_error_line(err)
    assert line.startswith(f"{path}:2: "), line
    assert "a timer's period must be a number of seconds >= 0, not 'abc'" in line


def test_parameters_apply_in_the_order_given_and_xml_sources_include(
    rosl: Rosl, launch_dir: Path
) -> None:
    (launch_dir / "slow.yaml").write_text("/**:\n  ros__parameters:\n    timer_period_s: 3.0\n")
    write_launch(
        launch_dir,
        "order.launch.xml",
        """
        <launch>
          <node pkg="tutorial_pkg" exec="timer_node" name="ordered">
            <param from="$(dirname)/slow.yaml"/>
            <param name="timer_period_s" value="0.5"/>
          </node>
        </launch>
        """,
    )
    parent = write_launch(
        launch_dir,
        "parent.launch.py",
        """
        import os

        from launch import LaunchDescription
        from launch.actions import IncludeLaunchDescription
        from launch_xml.launch_description_sources import XMLLaunchDescriptionSource


        def generate_launch_description():
            child = os.path.join(os.path.dirname(__file__), "order.launch.xml")
            return LaunchDescription([IncludeLaunchDescription(XMLLaunchDescriptionSource(child))])
        """,
    )
    launch = rosl.start("launch", str(parent))
    assert launch.wait_for(r"Timer period: 0\.5 s", "out", timeout=30.0), launch.both()
    assert launch.interrupt() == 0, launch.both()
