"""Nodes forked from the launcher's pre-imported interpreter behave as freshly started ones.

Every check runs twice: with the zygote (``ROSL_LAUNCH_ZYGOTE=1``, for ``python -P -m
rosl.pkg.entry`` command lines) and without it (a fresh interpreter per node), and the
launcher's view must be the same: output prefixes on stdout and stderr, the node's own
environment, working folder, arguments and session, exit codes, Ctrl-C.
"""

from __future__ import annotations

import os
import sys
from typing import TYPE_CHECKING

import pytest

from tests.launch.support import assert_all_gone, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Rosl

PROBE = """
import os
import sys
import time

print("cwd", os.getcwd())
print("env", os.environ.get("PROBE_WORD"), os.environ.get("ROSL_SIGINT_HELD"))
print("argv", sys.argv[1:])
print("leader", os.getsid(0) == os.getpid() == os.getpgid(0))
print("stdin", sys.stdin.read() == "")
print("to stderr", file=sys.stderr)
if os.environ.get("PROBE_WAIT"):
    try:
        print("waiting")
        while True:
            time.sleep(0.05)
    except KeyboardInterrupt:
        print("interrupted")
        sys.exit(0)
sys.exit(int(os.environ.get("PROBE_EXIT", "0")))
"""

LAUNCH = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess

ENTRY = [sys.executable, "-P", "-m", "rosl.pkg.entry", {folder!r}, {script!r}]


def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(cmd=[*ENTRY, "probe", "one", "two"], name="probe", output="screen",
                       cwd={cwd!r}, additional_env={{"PROBE_WORD": "hello"}}),
        ExecuteProcess(cmd=[*ENTRY, "failing"], name="failing", output="screen",
                       additional_env={{"PROBE_EXIT": "3"}}),
        ExecuteProcess(cmd=[*ENTRY, "waiting"], name="waiting", output="screen",
                       additional_env={{"PROBE_WAIT": "1"}}),
    ])
"""

MODES = [pytest.param({"ROSL_LAUNCH_ZYGOTE": "1"}, id="zygote"), pytest.param({}, id="fresh")]


@pytest.mark.parametrize("env", MODES)
def test_a_launched_rosl_entry_has_its_own_environment_folder_output_and_exit(
    rosl: Rosl, launch_dir: Path, tmp_path: Path, env: dict[str, str]
) -> None:
    script = launch_dir / "probe.py"
    script.write_text(PROBE, encoding="utf-8")
    cwd = tmp_path / "work"
    cwd.mkdir()
    source = LAUNCH.format(folder=str(launch_dir), script=str(script), cwd=str(cwd))
    path = write_launch(launch_dir, "probe.launch.py", source)

    launch = rosl.start("launch", str(path), env=env)

    assert launch.wait_for(r"process has died \[pid \d+, exit code 3, "), launch.both()
    assert launch.wait_for(r"^\[probe-1\] to stderr$"), launch.both()
    assert launch.wait_for(r"^\[waiting-3\] waiting$"), launch.both()  # Ctrl-C is caught now
    assert launch.wait_for(r"process has finished cleanly"), launch.both()
    out = launch.lines()
    assert f"[probe-1] cwd {cwd}" in out, launch.both()
    assert "[probe-1] env hello None" in out, launch.both()  # SIGINT was let in by the entry
    assert "[probe-1] argv ['one', 'two']" in out, launch.both()
    assert "[probe-1] leader True" in out, launch.both()
    assert "[failing-2] env None None" in out, launch.both()  # not the other node's variable
    pids = launch.pids()
    assert len(set(pids)) == 3
    assert launch.interrupt() == 1, launch.both()  # the failing node fails the launch
    assert "[waiting-3] interrupted" in launch.lines(), launch.both()
    assert "Traceback" not in launch.text("err")
    assert_all_gone(pids)


def test_a_node_with_its_own_pythonpath_starts_afresh_and_sees_it(
    rosl: Rosl, launch_dir: Path, tmp_path: Path
) -> None:
    extra = tmp_path / "extra"
    extra.mkdir()
    (extra / "probe_extra_module.py").write_text("WORD = 'from the extra path'\n")
    script = launch_dir / "uses_extra.py"
    script.write_text("import probe_extra_module\nprint(probe_extra_module.WORD)\n")
    path = write_launch(
        launch_dir,
        "extra.launch.py",
        f"""
        import sys
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess


        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(
                    cmd=[sys.executable, "-P", "-m", "rosl.pkg.entry", {str(launch_dir)!r},
                         {str(script)!r}, "extra"],
                    output="screen", additional_env={{"PYTHONPATH": {str(extra)!r}}},
                ),
            ])
        """,
    )

    launch = rosl.start("launch", str(path), env={"ROSL_LAUNCH_ZYGOTE": "1"})
    code = launch.finish(60.0)
    out, err = launch.text("out"), launch.text("err")

    assert code == 0, out + err
    assert "] from the extra path" in out, out + err


def test_the_zygote_is_not_used_for_other_interpreters_or_programs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from rosl.launch import zygote

    monkeypatch.setenv("ROSL_LAUNCH_ZYGOTE", "1")

    entry = [sys.executable, "-P", "-m", "rosl.pkg.entry", "pkg", "m:main", "name"]
    env = dict(os.environ)
    assert zygote.can_fork(entry, env)
    assert not zygote.can_fork(["/usr/bin/python3", *entry[1:]], env)
    assert not zygote.can_fork([sys.executable, "-m", "rosl", "run", "a", "b"], env)
    assert not zygote.can_fork(entry, {**env, "PYTHONPATH": "/elsewhere"})
    monkeypatch.delenv("ROSL_LAUNCH_ZYGOTE")
    assert not zygote.can_fork(entry, env)  # opt-in
