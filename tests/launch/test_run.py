"""``rosl run PKG EXECUTABLE``: find the executable through package.xml, run it, pass its exit on."""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from tests.conftest import write_package
from tests.launch.support import PYTHON, Output, assert_all_gone, one_error_line, write_launch

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.launch.support import Rosl

MANIFEST = """<?xml version="1.0"?>
<package format="3">
  <name>tools_pkg</name>
  <version>0.0.0</version>
  <export>
    <rosl>
      <executable name="exit_three">tools_pkg.exits:sys_exit_three</executable>
      <executable name="return_three">tools_pkg.exits:return_three</executable>
      <executable name="show_env">tools_pkg.exits:show_env</executable>
      <executable name="tool">scripts/tool.py</executable>
    </rosl>
  </export>
</package>
"""

EXITS = """
import os
import sys


def sys_exit_three():
    print("exiting with 3", flush=True)
    sys.exit(3)


def return_three():
    return 3


def show_env():
    print("FOO=" + os.environ.get("FOO", "<unset>"), flush=True)
"""

TOOL = """
import sys

print("tool ran with", sys.argv[1:], flush=True)
"""


@pytest.fixture
def tools_pkg(make_package: Callable[..., Path]) -> Path:
    """A workspace package with module executables and one declared as a file path."""
    return make_package(
        "tools_pkg",
        {
            "tools_pkg/__init__.py": "",
            "tools_pkg/exits.py": EXITS,
            "scripts/tool.py": TOOL,
        },
        manifest=MANIFEST,
    )


def test_run_starts_the_tutorial_timer_node_with_a_parameter_from_ros_args(rosl: Rosl) -> None:
    node = rosl.start(
        "run", "tutorial_pkg", "timer_node", "--ros-args", "-p", "timer_period_s:=0.2"
    )

    assert node.wait_for(r"\[timer_node\]: Timer period: 0\.2 s$", "err"), node.both()
    assert node.wait_for(r"\[timer_node\]: Tick 1 \(period 0\.2 s\)$", "err"), node.both()
    assert node.interrupt() == 0, node.both()
    assert "Traceback" not in node.text("err")


@pytest.mark.parametrize("executable", ["exit_three", "return_three"])
def test_run_exits_with_the_exit_code_of_the_executable(
    rosl: Rosl, tools_pkg: Path, executable: str
) -> None:
    code, _, err = rosl.run("run", "tools_pkg", executable)

    assert code == 3, err
    assert "Traceback" not in err


def test_run_prefix_wraps_the_command_like_ros2_run(
    rosl: Rosl, tools_pkg: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("FOO", raising=False)
    code, out, err = rosl.run("run", "--prefix", "env FOO=1", "tools_pkg", "show_env")

    assert code == 0, err
    assert out.splitlines() == ["FOO=1"]


def test_run_without_prefix_leaves_the_environment_alone(
    rosl: Rosl, tools_pkg: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("FOO", raising=False)
    code, out, err = rosl.run("run", "tools_pkg", "show_env")

    assert code == 0, err
    assert out.splitlines() == ["FOO=<unset>"]


def test_run_starts_an_executable_declared_as_a_file_path(rosl: Rosl, tools_pkg: Path) -> None:
    code, out, err = rosl.run("run", "tools_pkg", "tool", "a", "--b")

    assert code == 0, err
    assert out.splitlines() == ["tool ran with ['a', '--b']"]


def test_run_of_an_unknown_executable_lists_the_package_executables_closest_first(
    rosl: Rosl,
) -> None:
    code, out, err = rosl.run("run", "tutorial_pkg", "timer_nod")

    assert code == 1
    assert out == ""
    line = one_error_line(err)
    assert line == (
        "no executable 'timer_nod' in package 'tutorial_pkg'; it has: "
        "timer_node, count_images, my_publisher, my_subscriber, velocity_controller"
    )


def test_run_of_an_unknown_package_names_it_and_suggests_the_closest(rosl: Rosl) -> None:
    code, out, err = rosl.run("run", "tutorial_pk", "timer_node")

    assert code == 1
    assert out == ""
    line = one_error_line(err)
    assert line.startswith("package 'tutorial_pk' not found (did you mean 'tutorial_pkg'?)"), line


@pytest.mark.parametrize(
    ("ros_args", "message"),
    [
        (["--params-file", "nosuch.yaml"], "timer_node: --params-file nosuch.yaml: no such file"),
        (["--log-level", "bogus"], "timer_node: --log-level 'bogus': use one of debug, info, warn"),
        (["-r", "__node:=1bad"], "timer_node: --ros-args -r '__node:=1bad': invalid node name"),
        (["-p", "timer_period_s=0.2"], "timer_node: --ros-args -p 'timer_period_s=0.2': expected"),
        (["--foo"], "timer_node: unknown ROS argument '--foo'"),
    ],
    ids=["params-file", "log-level", "node-name", "param-rule", "unknown-flag"],
)
def test_run_reports_a_ros_args_mistake_in_one_line(
    rosl: Rosl, ros_args: list[str], message: str
) -> None:
    code, out, err = rosl.run("run", "tutorial_pkg", "timer_node", "--ros-args", *ros_args)

    assert code == 1
    assert out == ""
    assert one_error_line(err).startswith(message)


def test_run_names_the_executables_line_for_a_parameter_of_the_wrong_type(rosl: Rosl) -> None:
    code, _, err = rosl.run(
        "run", "tutorial_pkg", "timer_node", "--ros-args", "-p", "timer_period_s:=abc"
    )

    assert code == 1
    line = one_error_line(err)
    assert line.startswith("timer_node: ")
    assert "tutorial_pkg/timer_node.py:" in line  # where the code declares it
    assert "Wrong parameter type, parameter {timer_period_s} is of type {double}" in line


def test_run_reports_a_domain_out_of_range_in_one_line(
    rosl: Rosl, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROSL_DOMAIN_ID", "300")
    code, _, err = rosl.run("run", "tutorial_pkg", "timer_node")

    assert code == 1
    assert one_error_line(err) == (
        "timer_node: ROSL_DOMAIN_ID=300 is out of range: domain ids go from 0 to 232"
    )


def test_run_domain_id_option_is_checked_like_the_environment(rosl: Rosl) -> None:
    code, _, err = rosl.run("run", "--domain-id", "300", "tutorial_pkg", "timer_node")

    assert code == 1
    assert one_error_line(err) == "--domain-id=300 is out of range: domain ids go from 0 to 232"


def test_run_of_a_module_that_was_never_declared_says_how_to_declare_it(
    rosl: Rosl, make_package: Callable[..., Path]
) -> None:
    # the seed wrote velocity_controller but forgot to register it (add_executable/install)
    folder = make_package(
        "forgetful_pkg", {"forgetful_pkg/__init__.py": "", "forgetful_pkg/controller.py": ""}
    )
    code, _, err = rosl.run("run", "forgetful_pkg", "controller")

    assert code == 1
    assert one_error_line(err) == (
        "no executable 'controller' in package 'forgetful_pkg': "
        f"{folder / 'forgetful_pkg' / 'controller.py'} exists but is not declared; add "
        '<executable name="controller">forgetful_pkg.controller:main</executable> under '
        f"<export><rosl> in {folder / 'package.xml'}"
    )


def test_run_from_outside_the_workspace_names_the_workspace_that_has_the_package(
    rosl: Rosl, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the seed's "Package 'tutorial_pkg' not found" in a fresh terminal: no source to forget,
    # but a terminal outside ~/ros2_ws does not see it; say so in the one line
    home = tmp_path / "home"
    write_package(home / "ros2_ws" / "src", "seed_pkg")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir(elsewhere)

    code, _, err = rosl.run("run", "seed_pkg", "talker")

    assert code == 1
    src = home / "ros2_ws" / "src"
    assert one_error_line(err).endswith(
        f"; it is in {src / 'seed_pkg'}, a workspace not active here: run rosl from inside "
        f"{home / 'ros2_ws'} or export ROSL_PACKAGE_PATH={src}"
    )


def shadowing_folder(tmp_path: Path, init: str | None) -> Path:
    """A current folder holding a ``rosl/`` folder (a clone of rosl, say) that is not rosl."""
    folder = tmp_path / "home"
    (folder / "rosl").mkdir(parents=True)
    if init is not None:
        (folder / "rosl" / "__init__.py").write_text(init)
    return folder


def start_in(rosl: Rosl, cwd: Path, *args: str) -> Output:
    """Start ``rosl ARGS`` from ``cwd`` as the installed ``rosl`` script does (cwd not on path)."""
    output = Output(rosl.processes.start([PYTHON, "-P", "-m", "rosl", *args], cwd=cwd))
    rosl.watched.append(output)
    return output


@pytest.mark.parametrize(
    "init", [None, "raise ImportError('not rosl')\n"], ids=["empty", "bogus-init"]
)
def test_run_starts_the_node_when_the_current_folder_holds_a_rosl_folder(
    rosl: Rosl, tmp_path: Path, init: str | None
) -> None:
    # `cd ~ && rosl run ...` with an editable clone in ~/rosl: `python -m` put the current
    # folder first on sys.path, so ~/rosl shadowed the installed package
    home = shadowing_folder(tmp_path, init)

    node = start_in(rosl, home, "run", "tutorial_pkg", "timer_node")

    assert node.wait_for(r"\[timer_node\]: Timer period: 2\.0 s$", "err"), node.both()
    assert node.interrupt() == 0, node.both()
    assert "Traceback" not in node.text("err")


def test_launch_starts_the_nodes_when_the_current_folder_holds_a_rosl_folder(
    rosl: Rosl, tmp_path: Path, launch_dir: Path
) -> None:
    home = shadowing_folder(tmp_path, "raise ImportError('not rosl')\n")
    path = write_launch(
        launch_dir,
        "timer.launch.py",
        """
        from launch import LaunchDescription
        from launch_ros.actions import Node


        def generate_launch_description():
            return LaunchDescription([
                Node(package="tutorial_pkg", executable="timer_node", output="screen"),
            ])
        """,
    )

    launch = start_in(rosl, home, "launch", str(path))

    assert launch.wait_for(r"\[timer_node\]: Timer period: 2\.0 s$"), launch.both()
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    assert "Traceback" not in launch.text("err")
    assert_all_gone(pids)


TYPO_MANIFEST = """<?xml version="1.0"?>
<package format="3">
  <name>typo_pkg</name>
  <version>0.0.0</version>
  <export>
    <rosl>
      <executable name="timer_node">typo_pkg.timer_nod:main</executable>
      <executable name="talker">typo_pkg.timer_node:mian</executable>
      <executable name="listener">typo_pkg.listener:main</executable>
    </rosl>
  </export>
</package>
"""

LISTENER = """import rclpy

from typo_pkg.msg import MyDta


def main():
    rclpy.init()
"""


@pytest.fixture
def typo_pkg(make_package: Callable[..., Path]) -> Path:
    """A package whose executables point at a misspelt module and function, and import a typo."""
    return make_package(
        "typo_pkg",
        {
            "msg/MyData.msg": "int32 counter\n",
            "typo_pkg/__init__.py": "",
            "typo_pkg/timer_node.py": "def main():\n    pass\n\n\ndef helper():\n    pass\n",
            "typo_pkg/listener.py": LISTENER,
        },
        manifest=TYPO_MANIFEST,
    )


@pytest.mark.parametrize(
    ("executable", "message"),
    [
        (
            "timer_node",
            "package.xml:7: executable 'timer_node': module 'typo_pkg.timer_nod' not found "
            "(did you mean 'typo_pkg.timer_node'?)",
        ),
        (
            "talker",
            "package.xml:8: executable 'talker': module 'typo_pkg.timer_node' has no function "
            "'mian' (did you mean 'main'?)",
        ),
        (
            "listener",
            "typo_pkg/listener.py:3: cannot import name 'MyDta' from 'typo_pkg.msg' "
            "(did you mean 'MyData'?)",
        ),
    ],
    ids=["module", "function", "interface"],
)
def test_run_reports_a_misspelt_name_in_one_line_naming_the_file_and_the_closest_name(
    rosl: Rosl, typo_pkg: Path, executable: str, message: str
) -> None:
    code, out, err = rosl.run("run", "typo_pkg", executable)

    assert code == 1, err
    assert out == ""
    line = one_error_line(err)
    assert str(typo_pkg) in line
    assert line.endswith(message), line


def test_launch_shows_a_misspelt_executable_module_as_the_process_line(
    rosl: Rosl, typo_pkg: Path, launch_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "typos.launch.py",
        """
        from launch import LaunchDescription
        from launch_ros.actions import Node


        def generate_launch_description():
            return LaunchDescription([
                Node(package="typo_pkg", executable="timer_node", output="screen"),
                Node(package="typo_pkg", executable="listener", output="screen"),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))

    assert launch.finish() not in (0, None), launch.both()
    assert launch.matching(
        r"^\[timer_node-1\] \S+/package\.xml:7: executable 'timer_node': module "
        r"'typo_pkg\.timer_nod' not found \(did you mean 'typo_pkg\.timer_node'\?\)$"
    ), launch.both()
    assert launch.matching(
        r"^\[listener-2\] listener: \S+/typo_pkg/listener\.py:3: cannot import name 'MyDta' "
        r"from 'typo_pkg\.msg' \(did you mean 'MyData'\?\)$"
    ), launch.both()
    assert "Traceback" not in launch.text("out") + launch.text("err")
    assert_all_gone(launch.pids())


@pytest.mark.parametrize(("written", "shown"), [("-5.0", "-5.0"), (".nan", "nan")])
def test_run_with_a_params_file_period_that_no_timer_can_have_reports_one_line(
    rosl: Rosl, tmp_path: Path, written: str, shown: str
) -> None:
    params = tmp_path / "params.yaml"
    params.write_text(f"timer_node:\n  ros__parameters:\n    timer_period_s: {written}\n")

    code, out, err = rosl.run(
        "run", "tutorial_pkg", "timer_node", "--ros-args", "--params-file", str(params)
    )

    assert code == 1, err
    assert out == ""
    line = one_error_line(err)
    assert line.startswith("timer_node: "), line
    assert "tutorial_pkg/timer_node.py:" in line  # the create_timer call
    assert line.endswith(
        f"create_timer: timer_period_sec must be a finite number > 0, got {shown} "
        "(the value of parameter 'timer_period_s')"
    ), line
