"""ROS 2's XML launch format: every tag, one system written in Python, XML and YAML, errors.

The files are in ``frontend_files/``: ``every_tag.launch.xml`` uses every tag and substitution
rosl reads (its ``<log>`` lines show the values), ``system.launch.{py,xml,yaml}`` are one small
system written three times. ``--print`` runs in this process; each system style runs once as a
real launch.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from rosl.cli.main import main
from rosl.idl import registry
from rosl.launch import loader
from tests.launch.support import assert_all_gone, write_launch

if TYPE_CHECKING:
    from tests.launch.support import Rosl

FILES = Path(__file__).parent / "frontend_files"
EVERY_TAG = FILES / "every_tag.launch.xml"


class Cli:
    """``rosl ARGS`` in this process: (exit code, stdout, stderr)."""

    def __init__(self, capsys: pytest.CaptureFixture[str]) -> None:
        self.capsys = capsys

    def __call__(self, *args: str | Path) -> tuple[int, str, str]:
        registry.clear()
        loader.clear_cache()
        self.capsys.readouterr()
        code = main([str(a) for a in args])
        out, err = self.capsys.readouterr()
        return code, out, err

    def error(self, *args: str | Path) -> str:
        """The one stderr line of a user mistake (exit 1, nothing on stdout, no traceback)."""
        code, out, err = self(*args)
        assert code == 1, (out, err)
        assert "Traceback" not in err
        lines = err.splitlines()
        assert len(lines) == 1, err
        assert "process started" not in out
        return lines[0]


@pytest.fixture
def cli(capsys: pytest.CaptureFixture[str], log_dir: Path) -> Cli:
    """Run rosl in this process with the examples on the package path."""
    return Cli(capsys)


def users(out: str) -> list[str]:
    """The ``[launch.user]`` lines (what ``<log>`` printed), without their prefix."""
    prefix = "[INFO] [launch.user]: "
    return [line.removeprefix(prefix) for line in out.splitlines() if line.startswith(prefix)]


def block(out: str, label: str) -> list[str]:
    """The ``--print`` lines of one process: its command line and the indented lines after."""
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(f"[{label}] "))
    end = start + 1
    while end < len(lines) and lines[end].startswith("    "):
        end += 1
    return lines[start:end]


# --- every tag and substitution ------------------------------------------------------------


def test_every_substitution_resolves_as_launch_resolves_it(
    cli: Cli, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("ROSL_TEST_SURELY_UNSET", raising=False)

    code, out, err = cli("launch", EVERY_TAG, "--print")

    assert code == 0, err
    logged = users(out)
    share = str(FILES.parent.parent.parent / "examples" / "tutorial_pkg")
    assert logged[:5] == [
        "word=two words mode=fast env=fallback",  # optenv's default of two words; env's default
        "escaped $(var mode) and one \\ backslash",  # \$ and \\ as launch escapes them
        "eval=fastfast math=3 os=/ builtins=4",  # nested in quotes; math, a module, builtins
        "not=false and=false or=true",
        "command=from-command warned=w",  # stdout; stderr ignored when asked
    ]
    anon = re.fullmatch(r"anon=(a_\d+_\d+) again=(a_\d+_\d+) other=(b_\d+_\d+)", logged[5])
    assert anon is not None, logged[5]
    assert anon[1] == anon[2]  # the same name, the same anonymous name
    assert logged[6] == f"file={EVERY_TAG} dir={FILES}"
    assert logged[7] == f"share={share} prefix={share}"
    assert logged[8] == f"exec={shutil.which('sh')} nested=9"  # $(var $(var mode)_speed 9)


def test_groups_scope_arguments_and_conditions_guard_every_tag(cli: Cli) -> None:
    code, out, err = cli("launch", EVERY_TAG, "--print")

    assert code == 0, err
    assert users(out)[9:] == [
        "leaked=yes inside=no",  # scoped="false" lets <let> out; a scoped group does not
        "only=fast mode=unset",  # forwarding="false" passes only what <keep> names
        "unless false",  # if="false" left one <log> out
        "included with tags",  # <include> with an <arg>
    ]
    assert not any(line.startswith("[timer_node-") for line in out.splitlines())  # unless=


def test_a_node_tag_gives_its_command_line_parameters_and_remaps(cli: Cli) -> None:
    code, out, err = cli("launch", EVERY_TAG, "--print")

    assert code == 0, err
    node = block(out, "publisher-1")  # exec_name names the process
    command = node[0]
    assert command.startswith("[publisher-1] nice -n 5 ")  # launch-prefix
    assert " my_publisher --flag 'fast and more' --ros-args " in command  # args, quoted word
    assert " -r __node:=pub -r __ns:=/fast/inner " in command  # pushed namespace + own one
    assert command.endswith(" -r in:=out -r a:=b --log-level warn")  # set_remap, remap, ros_args
    assert node[1:] == [
        "    node: pub (package tutorial_pkg, namespace /fast/inner)",
        f"    param: (file) {FILES / 'params.yaml'} = '...'",
        "    param: as_string = '3'",  # type="str"
        "    param: flags = [True, False]",  # value-sep, each typed
        "    param: floats = [1.0, 2.5]",  # type="list_of_float"
        "    param: nested.deep.leaf = 'fast'",  # nested <param>s are dotted names
        "    param: number = 3",
        "    param: speed = 2.5",  # <set_parameter>
        "    param: text = 'hello'",
        "    remap: in -> out",
        "    remap: a -> b",
        "    output: screen; respawn",
    ]
    assert block(out, "lister-2") == [
        f"[lister-2] /bin/sh -c 'ls -l {FILES}'",  # <executable shell="true">
        "    output: log",
    ]


def test_the_other_branch_runs_with_another_argument(cli: Cli) -> None:
    code, out, err = cli("launch", EVERY_TAG, "--print", "mode:=slow")

    assert code == 0, err
    assert not any(line.startswith("[publisher-") for line in out.splitlines())
    assert block(out, "timer_node-1")[1] == (
        "    node: timer_node (package tutorial_pkg, namespace /slow)"
    )


def test_show_args_lists_xml_arguments_with_their_descriptions(cli: Cli) -> None:
    code, out, err = cli("launch", EVERY_TAG, "--show-args")

    assert code == 0, err
    assert out.splitlines() == [
        "Arguments (pass arguments as '<name>:=<value>'):",
        "",
        "    'mode':",
        "        How to run. Valid choices are: ['fast', 'slow']",  # worded as launch words it
        "        (default: 'fast')",
        "",
        "    'home':",
        "        A default from the environment",
        "        (default: EnvVar('HOME'))",
        "",
        "    'with_optional':",
        "        no description given",
        "        (default: 'false')",
        "",
        "    'optional'*:",
        "        Only declared with_optional:=true",
        "        (default: 'x')",
        "",
        "    'who':",
        "        Who included this file",
        "        (default: 'nobody')",
        "",
        "* argument(s) which are only declared if specific conditions occur",
    ]


def test_a_value_outside_an_arguments_choices_is_one_line(cli: Cli) -> None:
    line = cli.error("launch", EVERY_TAG, "--print", "mode:=medium")

    assert line == (
        f"{EVERY_TAG}:4: launch argument 'mode' is 'medium', but must be one of: fast, slow"
    )


# --- one system, three styles --------------------------------------------------------------

STYLES = ("py", "xml", "yaml")


def test_the_python_xml_and_yaml_systems_print_the_same_plan(cli: Cli) -> None:
    plans = {}
    for style in STYLES:
        code, out, err = cli("launch", FILES / f"system.launch.{style}", "--print", "label:=fancy")
        assert code == 0, (style, err)
        plans[style] = out

    assert plans["xml"] == plans["py"]
    assert plans["yaml"] == plans["py"]
    timer = block(plans["xml"], "timer_node-1")
    assert "-r __node:=system_timer -r __ns:=/demo -p shared:=7 -p timer_period_s:=0.4" in timer[0]
    assert timer[0].endswith(f"--params-file {FILES / 'params.yaml'} -r my_data:=system_data")
    assert block(plans["xml"], "env_echo-4")[0].endswith(f"{FILES / 'echo_env.py'} fancy")


def test_the_xml_and_yaml_systems_show_the_same_arguments(cli: Cli) -> None:
    shown = {style: cli("launch", FILES / f"system.launch.{style}", "-s")[1] for style in STYLES}

    assert shown["xml"] == shown["yaml"]
    assert shown["xml"].startswith(shown["py"])  # and the included file's (a known path)
    assert "'who':" in shown["xml"]


@pytest.mark.parametrize("style", STYLES)
def test_each_style_of_the_system_runs_the_same_way(rosl: Rosl, style: str) -> None:
    launch = rosl.start("launch", str(FILES / f"system.launch.{style}"), "label:=fancy")

    expected = [
        r"^\[timer_node-1\] .*\[demo\.system_timer\]: Timer period: 0\.4 s$",  # param, if
        r"^\[my_subscriber-3\] .*\[system_listener\]: I heard: counter=",  # ns + both remaps
        r"^\[env_echo-4\] greeting=hello fancy again extra=extra fancy args=\['fancy'\]$",
        r"^\[INFO\] \[launch\.user\]: included with fancy$",
        r"^\[INFO\] \[launch\.user\]: timer fired for fancy$",
    ]
    for pattern in expected:
        assert launch.wait_for(pattern, timeout=30.0), (pattern, launch.both())
    pids = launch.pids()
    assert launch.interrupt() == 0, launch.both()
    assert_all_gone(pids)


# --- mistakes: one line, file:line ---------------------------------------------------------

ERRORS = [
    ("<launch>\n  <nod pkg='a' exec='b'/>\n</launch>", 2, "unknown tag <nod> (did you mean 'node'?)"),
    ("<launch>\n  <node pkg='a' exec='b' nme='x'/>\n</launch>", 2,
     "unknown attribute 'nme' in <node> (did you mean 'name'?)"),
    ("<launch>\n\n  <node exec='b'/>\n</launch>", 3, "<node> needs the attribute 'pkg'"),
    ("<launch>\n  <group ns='robot'/>\n</launch>", 2,
     "unknown attribute 'ns' in <group>: ROS 2 puts a <push-ros-namespace namespace=...> first"),
    ("<launch>\n  <node pkg='tutorial_pkg' exec='timer_node'>\n    <parm name='x' value='1'/>"
     "\n  </node>\n</launch>", 3, "unknown tag <parm> in <node> (did you mean 'param'?)"),
    ("<launch>\n  <let name='a' value='$(var x'/>\n</launch>", 2,
     "bad substitution in '$(var x': '$(var' at column 1 is not closed with ')'"),
    ("<launch>\n  <let name='a' value='$(vr x)'/>\n</launch>", 2,
     "bad substitution in '$(vr x)': unknown substitution '$(vr)' (did you mean 'var'?)"),
    ("<launch>\n  <let name='a' value='$(anon)'/>\n</launch>", 2,
     "bad substitution in '$(anon)': $(anon) takes 1 argument(s), not 0"),
    ("<launch>\n  <let name='a' value=\"$(eval 'x' y z)\"/>\n</launch>", 2,
     "$(eval) takes 1 to 2 argument(s), not 3"),
    ("<launch>\n  <let name='a' value='$(eval 1+(2))'/>\n</launch>", 2,
     "'(' at column 10 inside an argument: quote the whole argument"),
    ("<launch>\n  <let name='a' value=\"$(eval 'x)\"/>\n</launch>", 2,
     "the quote ' at column 8 is not closed"),
    ("<launch>\n  <log message='x'/>\n  <let name='a' value='$(var nope)'/>\n</launch>", 3,
     "launch configuration 'nope' is not set: declare it with <arg name=\"nope\" default"),
    ("<launch>\n  <node pkg='a'>\n</launch>", 3, "not valid XML: mismatched tag"),
    ("<lunch/>", 1, "the root tag of a launch file is <launch>, not <lunch>"),
    ("<launch>\n  <log message='x' if='true' unless='true'/>\n</launch>", 2,
     "<log> cannot have both 'if' and 'unless'"),
    ("<launch>\n  <log message='x'>hello</log>\n</launch>", 2, "unexpected text 'hello' in <log>"),
    ("<launch>\n  <log message='x' if='maybe'/>\n</launch>", 2,
     "Unknown value for condition: 'maybe'"),
    ("<launch>\n  <group scoped='perhaps'/>\n</launch>", 2,
     "attribute 'scoped' of <group> must be a boolean (true/false, yes/no, on/off), not 'perhaps'"),
    ("<launch>\n  <let name='a' value=\"$(command 'false')\"/>\n</launch>", 2,
     "command 'false' exited with code 1"),
    ("<launch>\n  <let name='a' value=\"$(command 'sh -c &quot;echo oops &gt;&amp;2&quot;')\"/>"
     "\n</launch>", 2, "command 'sh -c \"echo oops >&2\"' wrote to stderr: oops"),
    ("<launch>\n  <let name='a' value='$(find-exec surely_no_such_exe)'/>\n</launch>", 2,
     "executable 'surely_no_such_exe' not found on the PATH"),
    ("<launch>\n  <let name='a' value='$(find-pkg-share surely_no_pkg)'/>\n</launch>", 2,
     "package 'surely_no_pkg' not found"),
    ("<launch>\n  <node pkg='tutorial_pkg' exec='nope'/>\n</launch>", 2,
     "no executable 'nope' in package 'tutorial_pkg'"),
    ("<launch>\n  <include file='/surely/not/there.launch.xml'/>\n</launch>", 2,
     "launch file /surely/not/there.launch.xml does not exist"),
    ("<launch>\n  <node pkg='tutorial_pkg' exec='timer_node'>\n"
     "    <param name='x' value='a' type='int'/>\n  </node>\n</launch>", 3,
     "parameter value 'a' is not of type int"),
    ("<launch>\n  <node pkg='tutorial_pkg' exec='timer_node'>\n"
     "    <param name='x' from='y.yaml'/>\n  </node>\n</launch>", 3,
     "<param> with 'from' has no 'name'"),
    ("<launch>\n  <executable cmd=\"echo 'open\"/>\n</launch>", 2,
     "attribute 'cmd' of <executable> has an unclosed '"),
    ("<launch>\n  <node_container pkg='a' exec='b' name='c' namespace='d'/>\n</launch>", 2,
     "<node_container> is not supported: it runs C++ components, which rosl cannot"),
    ("<launch>\n  <node pkg='tutorial_pkg' exec='timer_node' respawn_delay='soon'/>\n</launch>",
     2, "attribute 'respawn_delay' of <node> must be a number, not 'soon'"),
]  # fmt: skip


@pytest.mark.parametrize(("text", "line", "what"), ERRORS, ids=[e[2][:40] for e in ERRORS])
def test_a_mistake_is_one_line_naming_the_file_and_line(
    cli: Cli, launch_dir: Path, text: str, line: int, what: str
) -> None:
    path = write_launch(launch_dir, "bad.launch.xml", text)

    found = cli.error("launch", path, "--print")

    assert found.startswith(f"{path}:{line}: "), found
    assert what in found, found


def test_an_error_in_an_included_xml_file_names_that_file(cli: Cli, launch_dir: Path) -> None:
    write_launch(launch_dir, "child.launch.xml", "<launch>\n\n  <nod/>\n</launch>\n")
    parent = write_launch(
        launch_dir,
        "parent.launch.xml",
        '<launch>\n  <include file="$(dirname)/child.launch.xml"/>\n</launch>\n',
    )

    found = cli.error("launch", parent, "--print")

    assert found.startswith(f"{launch_dir / 'child.launch.xml'}:3: unknown tag <nod>"), found
