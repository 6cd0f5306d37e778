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
        "set_param_launch_test.py",
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


SCOPED = """
from launch import LaunchDescription
from launch.actions import GroupAction, LogInfo, ResetLaunchConfigurations, SetLaunchConfiguration
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node, RosTimer, SetParameter, SetParametersFromFile, SetUseSimTime

def generate_launch_description():
    return LaunchDescription([
        SetLaunchConfiguration("a", "1"),
        SetLaunchConfiguration("b", "2"),
        GroupAction([
            ResetLaunchConfigurations({"c": LaunchConfiguration("a")}),
            LogInfo(msg=["c=", LaunchConfiguration("c"), " b=",
                         LaunchConfiguration("b", default="gone")]),
        ]),
        LogInfo(msg=["outside b=", LaunchConfiguration("b")]),
        GroupAction([
            SetUseSimTime(True),
            SetParametersFromFile(PARAMS),
            SetParameter("after", 2),
            Node(package="tutorial_pkg", executable="timer_node", parameters=[{"own": 3}]),
        ]),
        RosTimer(period=0.2, actions=[LogInfo(msg="ros timer fired")]),
    ])
"""


def test_reset_configurations_parameters_from_file_sim_time_and_ros_timer(
    rosl: Rosl, launch_dir: Path
) -> None:
    params = launch_dir / "params.yaml"
    params.write_text("/**:\n  ros__parameters:\n    from_file: 1\n")
    path = write_launch(launch_dir, "scoped.launch.py", f"PARAMS = {str(params)!r}\n{SCOPED}")

    code, out, err = rosl.run("launch", "--print", str(path))

    assert code == 0, f"{out}\n{err}"
    command = next(line for line in out.splitlines() if line.startswith("[timer_node-1]"))
    assert "-p use_sim_time:=true -p after:=2 -p own:=3" in command, out
    assert command.endswith(f"--params-file {params}"), out
    assert "[timer_node-1]" in out
    said = [line.split("]: ", 1)[1] for line in out.splitlines() if "[launch.user]" in line]
    assert said == ["c=1 b=gone", "outside b=2"], out  # the timer never fires in --print
    timer = write_launch(
        launch_dir,
        "ros_timer.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import LogInfo
        from launch_ros.actions import RosTimer
        def generate_launch_description():
            return LaunchDescription([RosTimer(period=0.2, actions=[LogInfo(msg="fired")])])
        """,
    )
    code, out, err = rosl.run("launch", str(timer))
    assert code == 0, f"{out}\n{err}"
    assert "[INFO] [launch.user]: fired" in out, out


TYPED_SETUP = """
from launch import LaunchDescription
from launch.action import Action
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.launch_context import LaunchContext
from launch.launch_description import LaunchDescription as Description
from launch.some_substitutions_type import SomeSubstitutionsType
from launch.substitution import Substitution
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def launch_setup(context: LaunchContext, *args, **kwargs) -> list[Action]:
    robots = int(LaunchConfiguration("robots").perform(context))
    prefix: SomeSubstitutionsType = context.launch_configurations["prefix"]
    return [Node(package="tutorial_pkg", executable="timer_node", name=f"timer_{i}",
                 namespace=f"{prefix}{i}") for i in range(robots)]


def generate_launch_description() -> Description:
    assert issubclass(LaunchConfiguration, Substitution)
    return LaunchDescription([
        DeclareLaunchArgument("robots", default_value="2"),
        DeclareLaunchArgument("prefix", default_value="robot"),
        OpaqueFunction(function=launch_setup),
    ])
"""


def test_an_opaque_function_setup_typed_with_launchs_modules(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(launch_dir, "typed.launch.py", TYPED_SETUP)

    code, out, err = rosl.run("launch", "--print", str(path), "robots:=3")

    assert code == 0, f"{out}\n{err}"
    found = re.findall(r"node: (timer_\d) \(package tutorial_pkg, namespace (/robot\d)\)", out)
    assert found == [("timer_0", "/robot0"), ("timer_1", "/robot1"), ("timer_2", "/robot2")], out


def test_reset_parameters_from_file_sim_time_and_ros_timer_tags_in_xml(
    rosl: Rosl, launch_dir: Path
) -> None:
    params = launch_dir / "params.yaml"
    params.write_text("/**:\n  ros__parameters:\n    from_file: 1\n")
    path = write_launch(
        launch_dir,
        "tags.launch.xml",
        f"""
        <launch>
          <let name="a" value="1"/>
          <let name="b" value="2"/>
          <group>
            <reset><keep name="c" value="$(var a)"/></reset>
            <log message="c=$(var c) b=$(var b gone)"/>
          </group>
          <group>
            <set_use_sim_time value="true"/>
            <set_parameters_from_file filename="{params}"/>
            <node pkg="tutorial_pkg" exec="timer_node"/>
          </group>
          <ros_timer period="0.1"><log message="ros timer"/></ros_timer>
        </launch>
        """,
    )

    code, out, err = rosl.run("launch", "--print", str(path))

    assert code == 0, f"{out}\n{err}"
    assert "[INFO] [launch.user]: c=1 b=gone" in out, out
    command = next(line for line in out.splitlines() if line.startswith("[timer_node-1]"))
    assert command.endswith(f"--ros-args -p use_sim_time:=true --params-file {params}"), out


CUSTOM = """
import os

from launch import LaunchDescription, Substitution
from launch.actions import LogInfo
from launch.launch_description_sources import get_launch_description_from_any_launch_file
from launch.substitutions import LaunchConfiguration
from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions


class Shout(Substitution):
    def __init__(self, text):
        super().__init__()
        self.text = normalize_to_list_of_substitutions(text)

    def perform(self, context):
        return perform_substitutions(context, self.text).upper()


def generate_launch_description():
    inner = get_launch_description_from_any_launch_file(
        os.path.join(os.path.dirname(__file__), "inner.launch.xml"))
    return LaunchDescription([
        inner,
        LogInfo(msg=Shout(["hello ", LaunchConfiguration("who")])),
    ])
"""


def test_a_custom_substitution_and_a_description_loaded_from_a_file(
    rosl: Rosl, launch_dir: Path
) -> None:
    write_launch(
        launch_dir,
        "inner.launch.xml",
        '<launch>\n  <let name="who" value="world"/>\n  <log message="inner"/>\n</launch>\n',
    )
    path = write_launch(launch_dir, "custom.launch.py", CUSTOM)

    code, out, err = rosl.run("launch", str(path))

    assert code == 0, f"{out}\n{err}"
    said = [line.split("]: ", 1)[1] for line in out.splitlines() if "[launch.user]" in line]
    assert said == ["inner", "HELLO WORLD"], out


@pytest.mark.parametrize("suffix", ["py", "xml"])
def test_a_parameter_file_with_substitutions_reaches_the_node_substituted(
    rosl: Rosl, launch_dir: Path, suffix: str
) -> None:
    params = launch_dir / "timer.yaml"
    params.write_text("/**:\n  ros__parameters:\n    timer_period_s: $(var period)\n")
    source = (
        f"""
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument
        from launch_ros.actions import Node
        from launch_ros.descriptions import ParameterFile
        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("period", default_value="2.0"),
                Node(package="tutorial_pkg", executable="timer_node", output="screen",
                     parameters=[ParameterFile({str(params)!r}, allow_substs=True)]),
            ])
        """
        if suffix == "py"
        else f"""
        <launch>
          <arg name="period" default="2.0"/>
          <node pkg="tutorial_pkg" exec="timer_node" output="screen">
            <param from="{params}" allow_substs="true"/>
          </node>
        </launch>
        """
    )
    path = write_launch(launch_dir, f"substs.launch.{suffix}", source)
    launch = rosl.start("launch", str(path), "period:=0.25")

    assert launch.wait_for(r"\[timer_node-1\] .*Timer period: 0\.25 s", timeout=60), launch.both()
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    assert_all_gone(pids)


def test_a_bad_substitution_in_a_parameter_file_is_one_line(rosl: Rosl, launch_dir: Path) -> None:
    params = launch_dir / "bad.yaml"
    params.write_text("/**:\n  ros__parameters:\n    x: $(nope)\n")
    path = write_launch(
        launch_dir,
        "bad_substs.launch.xml",
        f"""
        <launch>
          <node pkg="tutorial_pkg" exec="timer_node">
            <param from="{params}" allow_substs="true"/>
          </node>
        </launch>
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err).startswith(
        f"{path}:2: {params}: bad substitution: unknown substitution '$(nope)'"
    ), err
