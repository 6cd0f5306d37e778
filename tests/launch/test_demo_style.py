"""Launch files and launch tests written in the style of ros2/demos (demo_nodes talker/listener
in XML and YAML, dummy_robot_bringup), ros2/examples' launch_testing_examples and geometry2's
test_tf2 launch tests, run for real; and the newer launch substitutions (equals, if, all, any),
launch.logging, and the one line for a Foxy-era Node argument.

The packages live in tests/launch/python_api (see its README), put on ROSL_PACKAGE_PATH.
"""

from __future__ import annotations

import os
import re
from typing import TYPE_CHECKING

import pytest

from tests.conftest import REPO
from tests.launch.support import EXAMPLES, assert_all_gone, one_error_line, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Rosl

PACKAGES = REPO / "tests" / "launch" / "python_api"
LAUNCH_TESTS = PACKAGES / "launch_testing_check" / "test"


@pytest.fixture(autouse=True)
def packages(log_dir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The test packages on the package path, before rosl's examples."""
    monkeypatch.setenv("ROSL_PACKAGE_PATH", f"{PACKAGES}{os.pathsep}{EXAMPLES}")


@pytest.mark.parametrize("file_name", ["talker_listener.launch.xml", "talker_listener.launch.yaml"])
def test_the_demos_talker_listener_in_xml_and_yaml_talk(rosl: Rosl, file_name: str) -> None:
    launch = rosl.start("launch", "demo_nodes_py", file_name)

    assert launch.wait_for(r"^\[listener-2\] .*I heard: \[Hello World: \d+\]", timeout=60), (
        launch.both()
    )
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    assert_all_gone(pids)


@pytest.mark.parametrize(
    "file_name", ["dummy_robot_bringup.launch.py", "dummy_robot_bringup.launch.xml"]
)
def test_a_robot_description_reaches_its_node_whole(rosl: Rosl, file_name: str) -> None:
    launch = rosl.start("launch", "dummy_robot_check", file_name)

    assert launch.wait_for(
        r"^\[description_echo-1\] .*robot 'single_rrbot' with links: world, base_link, arm_link$",
        timeout=60,
    ), launch.both()
    assert launch.wait_for(r"^\[INFO\] \[talker-2\]: process started", timeout=30), launch.both()
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    assert_all_gone(pids)


@pytest.mark.parametrize(
    "file_name",
    [
        "hello_world_launch_test.py",
        "check_node_launch_test.py",
        "check_msgs_launch_test.py",
        "check_multiple_nodes_launch_test.py",
        "static_publisher_launch_test.py",
    ],
)
def test_launch_tests_in_the_style_of_ros2_examples_pass(rosl: Rosl, file_name: str) -> None:
    code, out, err = rosl.run("launch_test", str(LAUNCH_TESTS / file_name), timeout=180)

    assert code == 0, f"{out}\n{err}"
    assert "FAILED" not in out + err, f"{out}\n{err}"
    assert re.search(r"Ran [1-9]\d* tests? in .*\n\nOK", out + err), f"{out}\n{err}"


SUBSTITUTIONS_XML = """
<launch>
  <arg name="mode" default="fast"/>
  <arg name="rate" default="1.0"/>
  <log message="equals: $(equals $(var mode) fast) $(equals $(var rate) 1) $(equals true 1)"/>
  <log message="not-equals: $(not-equals $(var mode) fast)"/>
  <log message="if: $(if $(equals $(var mode) fast) quick slow) $(if false a b)"/>
  <log message="all/any: $(all true yes 1) $(all true false) $(any false 0 on)"/>
  <log message="only when slow" if="$(not-equals $(var mode) fast)"/>
</launch>
"""
SUBSTITUTIONS_PY = """
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, LogInfo
from launch.conditions import IfCondition
from launch.substitutions import (AllSubstitution, AnySubstitution, EqualsSubstitution,
                                  IfElseSubstitution, LaunchConfiguration,
                                  NotEqualsSubstitution)
import launch.logging

def generate_launch_description():
    mode = LaunchConfiguration("mode")
    launch.logging.get_logger("my_launch").info("building the description")
    return LaunchDescription([
        DeclareLaunchArgument("mode", default_value="fast"),
        LogInfo(msg=["equals: ", EqualsSubstitution(mode, "fast"), " ",
                     EqualsSubstitution(1.0, 1), " ", EqualsSubstitution(True, "1")]),
        LogInfo(msg=["not-equals: ", NotEqualsSubstitution(mode, "fast")]),
        LogInfo(msg=["if: ", IfElseSubstitution(EqualsSubstitution(mode, "fast"), "quick", "slow"),
                     " ", IfElseSubstitution("false", "a", "b")]),
        LogInfo(msg=["all/any: ", AllSubstitution("true", "yes", "1"), " ",
                     AllSubstitution("true", "false"), " ", AnySubstitution("false", "0", "on")]),
        LogInfo(msg="only when slow", condition=IfCondition(NotEqualsSubstitution(mode, "fast"))),
    ])
"""


@pytest.mark.parametrize("suffix", ["xml", "py"])
@pytest.mark.parametrize("mode", ["fast", "slow"])
def test_equals_if_all_and_any_substitutions(
    rosl: Rosl, launch_dir: Path, suffix: str, mode: str
) -> None:
    source = SUBSTITUTIONS_XML if suffix == "xml" else SUBSTITUTIONS_PY
    path = write_launch(launch_dir, f"subs.launch.{suffix}", source)

    code, out, err = rosl.run("launch", str(path), f"mode:={mode}")

    assert code == 0, f"{out}\n{err}"
    said = [line.split("]: ", 1)[1] for line in out.splitlines() if "[launch.user]" in line]
    fast = mode == "fast"
    assert said == [
        f"equals: {str(fast).lower()} true true",
        f"not-equals: {str(not fast).lower()}",
        f"if: {'quick' if fast else 'slow'} b",
        "all/any: true false true",
        *([] if fast else ["only when slow"]),
    ], out
    if suffix == "py":
        assert "[INFO] [my_launch]: building the description" in out, out


def test_a_wrong_number_of_arguments_to_if_is_one_line(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir, "if.launch.xml", '<launch>\n  <log message="$(if true)"/>\n</launch>\n'
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err).startswith(f"{path}:2: bad substitution in '$(if true)': "), err
    assert "$(if) takes 2 to 3 argument(s), not 1" in err


def test_a_foxy_era_node_argument_is_one_line_with_its_new_name(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "foxy.launch.py",
        """
        from launch import LaunchDescription
        from launch_ros.actions import Node
        def generate_launch_description():
            return LaunchDescription([
                Node(package="demo_nodes_py", node_executable="talker", output="screen"),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err) == (
        f"{path}:5: Node(): node_executable= is now executable= (ROS 2 Dashing/Foxy's spelling, "
        "gone since Galactic)"
    )
