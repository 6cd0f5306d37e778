"""ROS 2's YAML launch format: arg, node and include entries, and errors naming file:line."""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.launch.support import PYTHON, assert_all_gone, one_error_line, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Output, Rosl

CHILD = """
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, LogInfo
from launch.substitutions import LaunchConfiguration


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("who", default_value="nobody"),
        LogInfo(msg=["included with ", LaunchConfiguration("who")]),
    ])
"""

SYSTEM = """
launch:
- arg:
    name: label
    default: plain
    description: Passed on to the included file
- node:
    pkg: tutorial_pkg
    exec: timer_node
    name: yaml_timer
    output: screen
    param:
    - {name: timer_period_s, value: 0.4}
- include:
    file: "$(dirname)/child.launch.py"
    arg:
    - {name: who, value: "label $(var label)"}
"""


def stop(launch: Output) -> None:
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    assert_all_gone(pids)


def test_a_yaml_launch_file_declares_arguments_starts_nodes_and_includes_files(
    rosl: Rosl, launch_dir: Path
) -> None:
    write_launch(launch_dir, "child.launch.py", CHILD)
    path = write_launch(launch_dir, "system.launch.yaml", SYSTEM)

    launch = rosl.start("launch", str(path), "label:=fancy")

    assert launch.wait_for(r"^\[timer_node-1\] .*\[yaml_timer\]: Timer period: 0\.4 s$"), (
        launch.both()
    )
    assert "[INFO] [launch.user]: included with label fancy" in launch.lines(), launch.both()
    stop(launch)


def test_show_args_lists_the_arguments_of_a_yaml_launch_file(rosl: Rosl, launch_dir: Path) -> None:
    write_launch(launch_dir, "child.launch.py", CHILD)
    path = write_launch(launch_dir, "system.launch.yaml", SYSTEM)

    code, out, err = rosl.run("launch", str(path), "--show-args")

    assert code == 0, err
    assert out.splitlines()[:5] == [
        "Arguments (pass arguments as '<name>:=<value>'):",
        "",
        "    'label':",
        "        Passed on to the included file",
        "        (default: 'plain')",
    ]


def test_a_yaml_node_parameter_value_may_use_a_launch_argument(
    rosl: Rosl, launch_dir: Path
) -> None:
    # ROS 2's frontends resolve substitutions in <param value=...> and read the result as YAML
    path = write_launch(
        launch_dir,
        "param_var.launch.yaml",
        """
        launch:
        - arg: {name: period, default: "0.4"}
        - node:
            pkg: tutorial_pkg
            exec: timer_node
            name: yaml_timer
            output: screen
            param:
            - {name: timer_period_s, value: $(var period)}
        """,
    )

    launch = rosl.start("launch", str(path), "period:=0.9")

    assert launch.wait_for(r"\[yaml_timer\]: Timer period: 0\.9 s$", timeout=30.0), launch.both()
    stop(launch)


def test_an_unknown_yaml_entry_is_one_line_naming_the_file_and_line(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "typo.launch.yaml",
        """
        launch:
        - arg: {name: x, default: "1"}
        - nod:
            pkg: tutorial_pkg
            exec: timer_node
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1
    assert "process started" not in out
    line = one_error_line(err)
    assert line.startswith(f"{path}:4: "), line
    assert "'nod'" in line


def test_invalid_yaml_is_one_line_naming_the_file_and_line(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "broken.launch.yaml",
        """
        launch:
        - node:
            pkg: tutorial_pkg
            exec: [timer_node
        """,
    )

    code, _, err = rosl.run("launch", str(path))

    assert code == 1
    line = one_error_line(err)
    assert line.startswith(f"{path}:"), line
    assert "not valid YAML" in line
    line_number = int(line[len(f"{path}:") :].split(":", 1)[0])
    assert line_number in (4, 5), line


def test_a_yaml_node_missing_its_package_names_the_file_and_line(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "no_pkg.launch.yaml",
        f"""
        launch:
        - executable: {{cmd: "{PYTHON} -c pass", name: fine}}
        - node:
            exec: timer_node
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1
    assert "process started" not in out
    assert one_error_line(err) == f"{path}:4: missing 'pkg:'"


def test_an_unknown_yaml_node_attribute_is_one_line_with_the_closest_name(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "attribute.launch.yaml",
        """
        launch:
        - node:
            pkg: tutorial_pkg
            exec: timer_node
            nme: t1
        """,
    )

    code, out, err = rosl.run("launch", str(path))

    assert code == 1
    assert "process started" not in out
    line = one_error_line(err)
    assert line.startswith(f"{path}:3: unknown attribute 'nme' in 'node' (did you mean 'name'?)")
