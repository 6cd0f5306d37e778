"""Launch's ForLoop and ForEach (the newest distros') in Python, XML and YAML: the loop body
once per index or value set, ``$(index)`` / ``$(for-var)`` in it, mistakes in one line."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import pytest

from tests.launch.support import one_error_line, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Rosl

ROBOTS = "{name: 'robotA', id: 1};{name: 'robotB', id: 2}"
SOURCES = {
    "xml": f"""
        <launch>
          <arg name="num" default="2"/>
          <arg name="robots" default="{ROBOTS}"/>
          <for len="$(var num)" name="i">
            <log message="i=$(index i)"/>
          </for>
          <for_each values="$(var robots)">
            <log message="robot '$(for-var name)' id=$(for-var id) x=$(for-var x none)"/>
            <node pkg="tutorial_pkg" exec="timer_node" name="timer_$(for-var name)"/>
          </for_each>
        </launch>
        """,
    "yaml": f"""
        launch:
        - arg: {{name: num, default: '2'}}
        - arg: {{name: robots, default: "{ROBOTS}"}}
        - for:
            len: $(var num)
            name: i
            children:
            - log: {{message: "i=$(index i)"}}
        - for_each:
            values: $(var robots)
            children:
            - log: {{message: "robot '$(for-var name)' id=$(for-var id) x=$(for-var x none)"}}
            - node: {{pkg: tutorial_pkg, exec: timer_node, name: "timer_$(for-var name)"}}
        """,
    "py": f"""
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument, ForEach, ForLoop, LogInfo
        from launch.substitutions import LaunchConfiguration
        from launch_ros.actions import Node

        def for_i(i: int):
            return [LogInfo(msg=["i=", str(i)])]

        def for_each(id: int, name: str, x: str = "none"):
            return [LogInfo(msg=f"robot '{{name}}' id={{id}} x={{x}}"),
                    Node(package="tutorial_pkg", executable="timer_node", name=f"timer_{{name}}")]

        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("num", default_value="2"),
                DeclareLaunchArgument("robots", default_value="{ROBOTS}"),
                ForLoop(LaunchConfiguration("num"), function=for_i),
                ForEach(LaunchConfiguration("robots"), function=for_each),
            ])
        """,
}


@pytest.mark.parametrize("suffix", ["xml", "yaml", "py"])
def test_for_and_for_each_repeat_their_body(rosl: Rosl, launch_dir: Path, suffix: str) -> None:
    path = write_launch(launch_dir, f"loops.launch.{suffix}", SOURCES[suffix])

    code, out, err = rosl.run(
        "launch", "--print", str(path), "num:=3", "robots:={name: c, id: 3, x: 7};{name: d, id: 4}"
    )

    assert code == 0, f"{out}\n{err}"
    said = [line.split("]: ", 1)[1] for line in out.splitlines() if "[launch.user]" in line]
    assert said == ["i=0", "i=1", "i=2", "robot 'c' id=3 x=7", "robot 'd' id=4 x=none"], out
    assert re.findall(r"node: (timer_\w+) ", out) == ["timer_c", "timer_d"], out


def test_an_unknown_loop_variable_is_one_line_at_its_tag(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "bad_loop.launch.xml",
        """
        <launch>
          <for len="1" name="i">
            <log message="$(index j)"/>
          </for>
        </launch>
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err) == (
        f"{path}:3: loop variable 'j' is not set (this iteration has: i)"
    )


def test_a_value_set_that_is_no_mapping_is_one_line(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "bad_values.launch.xml",
        """
        <launch>
          <for_each values="{name: a};[1, 2]">
            <log message="$(for-var name)"/>
          </for_each>
        </launch>
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1, f"{out}\n{err}"
    assert one_error_line(err) == (
        f"{path}:2: for_each: '[1, 2]' is not a YAML mapping such as {{name: a, id: 1}}"
    )
