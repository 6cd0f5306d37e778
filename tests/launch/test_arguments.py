"""``rosl launch`` arguments: ``name:=value``, ``--show-args``, missing/malformed ones, ``--print``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.launch.support import PYTHON, STARTED, assert_all_gone, one_error_line, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Rosl

GREETER = f"""
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration


def generate_launch_description():
    return LaunchDescription([
        DeclareLaunchArgument("greeting", default_value="hello", description="What to say"),
        DeclareLaunchArgument("target", description="Whom to greet"),
        ExecuteProcess(
            cmd=[{PYTHON!r}, "-c", "import sys; print(' '.join(sys.argv[1:]))",
                 LaunchConfiguration("greeting"), LaunchConfiguration("target")],
            name="greeter",
            output="screen",
        ),
    ])
"""


def test_launch_arguments_reach_launch_configurations_and_the_last_of_a_name_wins(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "greeter.launch.py", GREETER)

    launch = rosl.start("launch", str(path), "greeting:=hi", "target:=there", "greeting:=hey")

    assert launch.finish() == 0, launch.both()
    assert "[greeter-1] hey there" in launch.lines(), launch.both()
    assert_all_gone(launch.pids())


def test_launch_argument_defaults_apply_when_not_given(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(launch_dir, "greeter.launch.py", GREETER)

    launch = rosl.start("launch", str(path), "target:=world")

    assert launch.finish() == 0, launch.both()
    assert "[greeter-1] hello world" in launch.lines(), launch.both()
    assert_all_gone(launch.pids())


def test_show_args_prints_declared_arguments_in_the_ros2_launch_format(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "greeter.launch.py", GREETER)

    code, out, err = rosl.run("launch", str(path), "--show-args")

    assert code == 0, err
    assert out == (
        "Arguments (pass arguments as '<name>:=<value>'):\n"
        "\n"
        "    'greeting':\n"
        "        What to say\n"
        "        (default: 'hello')\n"
        "\n"
        "    'target':\n"
        "        Whom to greet"
    )
    assert not STARTED.search(out)


def test_show_args_marks_conditionally_declared_arguments_and_says_when_there_are_none(
    rosl: Rosl, launch_dir: Path
) -> None:
    conditional = write_launch(
        launch_dir,
        "conditional.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument, GroupAction
        from launch.conditions import IfCondition
        from launch.substitutions import LaunchConfiguration


        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("use_extra", default_value="false"),
                GroupAction(
                    [DeclareLaunchArgument("extra", default_value="1", description="Extra")],
                    condition=IfCondition(LaunchConfiguration("use_extra")),
                ),
                DeclareLaunchArgument(  # its own condition marks it too
                    "own", default_value="2", condition=IfCondition("true"), choices=["2", "3"]
                ),
            ])
        """,
    )
    empty = write_launch(
        launch_dir,
        "empty.launch.py",
        """
        from launch import LaunchDescription


        def generate_launch_description():
            return LaunchDescription([])
        """,
    )

    code, out, err = rosl.run("launch", str(conditional), "--show-args")
    assert code == 0, err
    assert out == (
        "Arguments (pass arguments as '<name>:=<value>'):\n"
        "\n"
        "    'use_extra':\n"
        "        no description given\n"
        "        (default: 'false')\n"
        "\n"
        "    'extra'*:\n"
        "        Extra\n"
        "        (default: '1')\n"
        "\n"
        "    'own'*:\n"
        "        One of: ['2', '3']\n"
        "        (default: '2')\n"
        "\n"
        "* argument(s) which are only declared if specific conditions occur"
    )

    code, out, err = rosl.run("launch", str(empty), "--show-args")
    assert code == 0, err
    assert out == "Arguments (pass arguments as '<name>:=<value>'):\n\n  No arguments."


def test_show_args_describes_substitution_defaults_as_ros2_does(
    rosl: Rosl, launch_dir: Path
) -> None:
    # launch's TextSubstitution.describe() quotes the text once: LaunchConfig('name')
    path = write_launch(
        launch_dir,
        "defaults.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument
        from launch.substitutions import EnvironmentVariable, LaunchConfiguration


        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("first", default_value="a"),
                DeclareLaunchArgument("second", default_value=LaunchConfiguration("first")),
                DeclareLaunchArgument("home", default_value=EnvironmentVariable("HOME")),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(path), "--show-args")

    assert code == 0, err
    lines = out.splitlines()
    assert "        (default: LaunchConfig('first'))" in lines, out
    assert "        (default: EnvVar('HOME'))" in lines, out


def test_a_missing_launch_argument_is_one_line_saying_which_and_how_to_pass_it(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(launch_dir, "greeter.launch.py", GREETER)

    launch = rosl.start("launch", str(path), "greeting:=hi")

    assert launch.finish() == 1, launch.both()
    line = one_error_line(launch.text("err"))
    assert "'target'" in line
    assert "target:=<value>" in line
    assert launch.pids() == [], launch.both()


def test_a_missing_launch_argument_starts_nothing_even_if_a_process_comes_before_it(
    rosl: Rosl, launch_dir: Path
) -> None:
    # ros2 launch includes the file with IncludeLaunchDescription, which checks every
    # declared argument before any of the file's actions run
    marker = launch_dir / "ran"
    path = write_launch(
        launch_dir,
        "late_declaration.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument, ExecuteProcess


        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd=["touch", {str(marker)!r}], name="early"),
                DeclareLaunchArgument("needed", description="Must be given"),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.finish() == 1, launch.both()
    line = one_error_line(launch.text("err"))
    assert "needed:=<value>" in line
    assert launch.pids() == [], f"a process started before the argument check\n{launch.both()}"
    assert not marker.exists()


def test_a_malformed_launch_argument_gets_the_ros2_message(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(launch_dir, "greeter.launch.py", GREETER)

    code, out, err = rosl.run("launch", str(path), "target=world")

    assert code == 1
    assert not STARTED.search(out)
    assert one_error_line(err) == (
        "malformed launch argument 'target=world', expected format '<name>:=<value>'"
    )


def test_a_launch_file_missing_from_the_package_is_one_line(rosl: Rosl) -> None:
    code, _, err = rosl.run("launch", "tutorial_pkg", "no_such.launch.py")

    assert code == 1
    assert one_error_line(err).startswith(
        "file 'no_such.launch.py' was not found in the share directory of package 'tutorial_pkg'"
    )


def test_print_shows_command_lines_remaps_and_parameters_without_starting_anything(
    rosl: Rosl, launch_dir: Path
) -> None:
    marker = launch_dir / "ran"
    path = write_launch(
        launch_dir,
        "plan.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument, ExecuteProcess
        from launch.substitutions import LaunchConfiguration
        from launch_ros.actions import Node


        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("topic", default_value="/remapped"),
                Node(
                    package="tutorial_pkg",
                    executable="my_publisher",
                    name="talker",
                    namespace="demo",
                    parameters=[{{"rate": 2.0}}],
                    remappings=[("my_data", LaunchConfiguration("topic"))],
                    output="screen",
                ),
                ExecuteProcess(cmd=["touch", {str(marker)!r}], name="toucher"),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(path), "topic:=/elsewhere", "--print")

    assert code == 0, err
    lines = out.splitlines()
    talker = next(line for line in lines if line.startswith("[my_publisher-1] "))
    assert "tutorial_pkg.my_publisher:main" in talker
    assert " --ros-args " in talker
    assert "-r __node:=talker" in talker
    assert "-r __ns:=/demo" in talker
    assert "-r my_data:=/elsewhere" in talker
    assert " -p rate:=2.0" in talker  # typed as a user would: it runs as printed
    assert "--params-file" not in talker  # no file that --print did not write
    assert "    param: rate = 2.0" in lines
    assert "    remap: my_data -> /elsewhere" in lines
    assert any(line.startswith("[toucher-2] touch ") for line in lines), out
    assert not STARTED.search(out)
    assert not marker.exists()


def test_show_args_lists_the_arguments_of_files_included_through_substitutions(
    rosl: Rosl, launch_dir: Path
) -> None:
    # launch's IncludeLaunchDescription.get_sub_entities() expands the path with an empty
    # context, so ros2 launch --show-args lists an included file's arguments
    write_launch(
        launch_dir,
        "child.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument


        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("who", default_value="nobody", description="Child arg"),
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
                    PythonLaunchDescriptionSource(PathJoinSubstitution([here, "child.launch.py"]))
                ),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(parent), "--show-args")

    assert code == 0, err
    assert out.splitlines() == [
        "Arguments (pass arguments as '<name>:=<value>'):",
        "",
        "    'who':",
        "        Child arg",
        "        (default: 'nobody')",
    ]


def test_a_required_argument_of_an_included_file_is_satisfied_by_the_include(
    rosl: Rosl, launch_dir: Path
) -> None:
    # launch checks an included file's required arguments against the include's
    # launch_arguments (get_launch_arguments_with_include_launch_description_actions)
    write_launch(
        launch_dir,
        "child.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument, LogInfo
        from launch.substitutions import LaunchConfiguration


        def generate_launch_description():
            return LaunchDescription([
                DeclareLaunchArgument("who", description="Given by the parent"),
                LogInfo(msg=["child got ", LaunchConfiguration("who")]),
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


        def generate_launch_description():
            child = os.path.join(os.path.dirname(__file__), "child.launch.py")
            return LaunchDescription([
                IncludeLaunchDescription(
                    PythonLaunchDescriptionSource(child),
                    launch_arguments={"who": "the parent"}.items(),
                ),
            ])
        """,
    )

    code, out, err = rosl.run("launch", str(parent))

    assert code == 0, err
    assert "[INFO] [launch.user]: child got the parent" in out.splitlines()


def test_a_required_argument_missing_for_an_included_file_is_one_line_saying_how_to_pass_it(
    rosl: Rosl, launch_dir: Path
) -> None:
    write_launch(
        launch_dir,
        "child.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import DeclareLaunchArgument


        def generate_launch_description():
            return LaunchDescription([DeclareLaunchArgument("who", description="Needed")])
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


        def generate_launch_description():
            child = os.path.join(os.path.dirname(__file__), "child.launch.py")
            return LaunchDescription([IncludeLaunchDescription(PythonLaunchDescriptionSource(child))])
        """,
    )

    code, out, err = rosl.run("launch", str(parent))

    assert code == 1
    assert "process started" not in out
    line = one_error_line(err)
    assert "'who'" in line
    assert "who:=<value>" in line
