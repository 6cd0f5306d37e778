"""ROS 2's YAML launch format: arg, node and include entries, and errors naming file:line.

YAML files take the path XML files take (``rosl.launch.frontend``): tags, attributes and
``$(...)`` substitutions are the same; tests/launch/test_xml_format.py runs one system written
in Python, XML and YAML.
"""

from __future__ import annotations

import re
import shutil
from typing import TYPE_CHECKING

import pytest

from rosl.cli.main import main
from rosl.idl import registry
from rosl.launch import loader
from tests.launch.support import EXAMPLES, PYTHON, assert_all_gone, one_error_line, write_launch

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
    assert one_error_line(err) == f"{path}:4: 'node' needs the attribute 'pkg'"


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


# --- in this process: what --print shows -----------------------------------------------------


def print_plan(capsys: pytest.CaptureFixture[str], path: Path, *args: str) -> tuple[int, str, str]:
    """``rosl launch PATH --print ARGS`` in this process: (exit code, stdout, stderr)."""
    registry.clear()
    loader.clear_cache()
    capsys.readouterr()
    code = main(["launch", str(path), "--print", *args])
    out, err = capsys.readouterr()
    return code, out, err


def logged(out: str) -> list[str]:
    prefix = "[INFO] [launch.user]: "
    return [line.removeprefix(prefix) for line in out.splitlines() if line.startswith(prefix)]


def test_yaml_strings_take_every_substitution_command_included(
    capsys: pytest.CaptureFixture[str], launch_dir: Path, log_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "substitutions.launch.yaml",
        r"""
        launch:
        - arg: {name: mode, default: fast}
        - log: {message: "command=$(command 'printf \"from a command\"')"}
        - log: {message: "eval=$(eval '\"$(var mode)\" * 2') not=$(not $(var flag false))"}
        - log: {message: "optenv=$(optenv ROSL_TEST_SURELY_UNSET two words) escaped=\\$(var x)"}
        - log: {message: "anon=$(anon a) again=$(anon a)"}
        - log: {message: "file=$(filename) dir=$(dirname)"}
        - log: {message: "prefix=$(find-pkg-prefix tutorial_pkg) exec=$(find-exec sh)"}
        - log: {message: "and=$(and true 0) or=$(or true 0)", if: "$(eval '1 < 2')"}
        """,
    )

    code, out, err = print_plan(capsys, path)

    assert code == 0, err
    lines = logged(out)
    assert lines[:3] == [
        "command=from a command",
        "eval=fastfast not=true",
        "optenv=two words escaped=$(var x)",
    ]
    anon = re.fullmatch(r"anon=(a_\d+_\d+) again=(a_\d+_\d+)", lines[3])
    assert anon is not None, lines[3]
    assert anon[1] == anon[2]
    assert lines[4] == f"file={path} dir={launch_dir}"
    assert lines[5] == f"prefix={EXAMPLES / 'tutorial_pkg'} exec={shutil.which('sh')}"
    assert lines[6] == "and=false or=true"


def test_yaml_parameters_keep_their_yaml_types(
    capsys: pytest.CaptureFixture[str], launch_dir: Path, log_dir: Path
) -> None:
    path = write_launch(
        launch_dir,
        "params.launch.yaml",
        """
        launch:
        - arg: {name: period, default: "0.4"}
        - node:
            pkg: tutorial_pkg
            exec: timer_node
            param:
            - {name: a_float, value: 0.5}
            - {name: quoted, value: "0.5"}
            - {name: substituted, value: $(var period)}
            - {name: as_text, value: $(var period), type: str}
            - {name: a_list, value: [1, 2]}
            - {name: outer, param: [{name: inner, value: true}]}
        """,
    )

    code, out, err = print_plan(capsys, path)

    assert code == 0, err
    assert [line for line in out.splitlines() if line.startswith("    param: ")] == [
        "    param: a_float = 0.5",
        "    param: a_list = [1, 2]",
        "    param: as_text = '0.4'",
        "    param: outer.inner = True",
        "    param: quoted = '0.5'",
        "    param: substituted = 0.4",
    ]


@pytest.mark.parametrize(
    ("text", "line", "what"),
    [
        ("launch:\n- log: {message: x, if: 'true', unless: 'true'}\n", 2,
         "'log' cannot have both 'if' and 'unless'"),
        ("launch:\n- let:\n    name: a\n    value: $(var x\n", 3,
         "bad substitution in '$(var x': '$(var' at column 1 is not closed with ')'"),
        ("launch:\n- node:\n    pkg: tutorial_pkg\n    exec: timer_node\n    param:\n"
         "    - {name: a, vlue: 1}\n", 6, "unknown attribute 'vlue' in 'param' (did you mean"),
        ("launch:\n- group: {scoped: 'perhaps', children: []}\n", 2,
         "attribute 'scoped' of 'group' must be a boolean (true/false, yes/no, on/off), "
         "not 'perhaps'"),
        ("launch:\n- group: {scoped: true}\n", 2, "'group' needs 'children:'"),
        ("launch:\n- arg: {name: x}\n- log: {message: $(var y)}\n", 3,
         "launch configuration 'y' is not set: declare it with '- arg: {name: y, default: ...}'"),
    ],
)  # fmt: skip
def test_a_yaml_mistake_is_one_line_naming_the_file_and_line(
    capsys: pytest.CaptureFixture[str],
    launch_dir: Path,
    log_dir: Path,
    text: str,
    line: int,
    what: str,
) -> None:
    path = launch_dir / "bad.launch.yaml"
    path.write_text(text)

    code, out, err = print_plan(capsys, path, "x:=1")

    assert code == 1, (out, err)
    found = one_error_line(err)
    assert found.startswith(f"{path}:{line}: {what}"), found
