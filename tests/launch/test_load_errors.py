"""Broken launch files: one stderr line naming file:line, exit 1, no traceback, nothing started."""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.launch.support import one_error_line, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Rosl


def launch_fails(rosl: Rosl, path: Path) -> str:
    """Run ``rosl launch PATH``; it must exit 1 having started nothing; return its one line."""
    code, out, err = rosl.run("launch", str(path))
    assert code == 1, f"exit {code}\n{out}\n{err}"
    assert "process started" not in out
    return one_error_line(err)


def test_a_syntax_error_is_one_line_with_file_line_and_column(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "syntax.launch.py",
        """
        from launch import LaunchDescription


        def generate_launch_description(:
            return LaunchDescription([])
        """,
    )

    line = launch_fails(rosl, path)

    assert line.startswith(f"{path}:4:"), line
    column = line[len(f"{path}:4:") :].split(":", 1)[0]
    assert column.isdigit(), line
    assert int(column) > 0, line
    assert "syntax error" in line


def test_an_exception_while_generating_names_the_line_and_the_exception(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "raises.launch.py",
        """
        from launch import LaunchDescription


        def generate_launch_description():
            settings = {"robots": 2}
            return LaunchDescription([settings["cameras"]])
        """,
    )

    line = launch_fails(rosl, path)

    assert line == f"{path}:6: KeyError: 'cameras'"


def test_an_exception_at_import_time_names_the_line_and_the_exception(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "import_time.launch.py",
        """
        from launch import LaunchDescription

        RATE = 1 / 0


        def generate_launch_description():
            return LaunchDescription([])
        """,
    )

    line = launch_fails(rosl, path)

    assert line == f"{path}:3: ZeroDivisionError: division by zero"


def test_a_file_without_generate_launch_description_says_so(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "nothing.launch.py",
        """
        from launch import LaunchDescription


        def generate_description():
            return LaunchDescription([])
        """,
    )

    line = launch_fails(rosl, path)

    assert line.startswith(f"{path}: ")
    assert "generate_launch_description" in line


def test_generate_launch_description_returning_something_else_says_what(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "returns_list.launch.py",
        """
        def generate_launch_description():
            return []
        """,
    )

    line = launch_fails(rosl, path)

    assert line.startswith(f"{path}: ")
    assert "list" in line
    assert "LaunchDescription" in line


def test_an_unsupported_launch_name_is_one_line_naming_it_and_the_import_line(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "unsupported.launch.py",
        """
        from launch import LaunchDescription
        from launch.actions import SomethingElse


        def generate_launch_description():
            return LaunchDescription([SomethingElse()])
        """,
    )

    line = launch_fails(rosl, path)

    assert line.startswith(f"{path}:2: "), line
    assert "'launch.actions.SomethingElse' is not supported" in line


def test_an_unsupported_launch_ros_name_used_as_an_attribute_is_reported_too(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "unsupported_attribute.launch.py",
        """
        import launch
        import launch_ros.actions


        def generate_launch_description():
            return launch.LaunchDescription([
                launch_ros.actions.ComposableNodeContainer(name="c"),
            ])
        """,
    )

    line = launch_fails(rosl, path)

    assert line.startswith(f"{path}:7: "), line
    assert "'launch_ros.actions.ComposableNodeContainer' is not supported" in line


def test_a_node_of_an_unknown_package_is_one_line_naming_it(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "unknown_package.launch.py",
        """
        from launch import LaunchDescription
        from launch_ros.actions import Node


        def generate_launch_description():
            return LaunchDescription([Node(package="tutorial_pk", executable="timer_node")])
        """,
    )

    line = launch_fails(rosl, path)

    assert "package 'tutorial_pk' not found" in line
    assert "'tutorial_pkg'" in line
