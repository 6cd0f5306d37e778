"""Nodes forked from the launcher's pre-imported interpreter behave as freshly started ones.

The shared checks run twice: with the zygote (the default for ``python -P -m rosl.pkg.entry``
command lines) and without it (``ROSL_LAUNCH_ZYGOTE=0``: a fresh interpreter per node), and
the launcher's view must be the same: output prefixes on stdout and stderr, the node's own
environment, working folder, arguments and session, exit codes, Ctrl-C. A probe prints its
parent: the launcher for a fresh interpreter, the zygote for a forked node. Then the zygote's
hazards, each with real processes: threads at fork time, pids reaped before the launcher read
the exit, a zygote that does not answer, a zygote that dies, start-up-only variables, and the
zygote's own output.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.conftest import wait_until
from tests.launch.support import assert_all_gone, running, write_launch

if TYPE_CHECKING:
    from tests.conftest import Processes
    from tests.launch.support import Output, Rosl

PROBE = """
import os
import sys
import time

print("cwd", os.getcwd())
print("env", os.environ.get("PROBE_WORD"), os.environ.get("ROSL_SIGINT_HELD"))
print("argv", sys.argv[1:])
print("orig", sys.orig_argv[1:4], sys.orig_argv[-2:])
print("leader", os.getsid(0) == os.getpid() == os.getpgid(0))
print("stdin", sys.stdin.read() == "")
print("parent", os.getppid())
print("zone", time.tzname[0], "utf8", sys.flags.utf8_mode)
if os.environ.get("PROBE_IGNORE_TERM"):
    import signal

    signal.signal(signal.SIGTERM, signal.SIG_IGN)
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

MODES = [
    pytest.param({"ROSL_LAUNCH_ZYGOTE": "1"}, id="zygote"),
    pytest.param({"ROSL_LAUNCH_ZYGOTE": "0"}, id="fresh"),
]


def _three_probes(launch_dir: Path, cwd: Path) -> Path:
    """The three probes' launch file, the first started in ``cwd``."""
    script = launch_dir / "probe.py"
    script.write_text(PROBE, encoding="utf-8")
    source = LAUNCH.format(folder=str(launch_dir), script=str(script), cwd=str(cwd))
    return write_launch(launch_dir, "probe.launch.py", source)


@pytest.mark.parametrize("env", MODES)
def test_a_launched_rosl_entry_has_its_own_environment_folder_output_and_exit(
    rosl: Rosl, launch_dir: Path, tmp_path: Path, env: dict[str, str]
) -> None:
    cwd = tmp_path / "work"
    cwd.mkdir()
    path = _three_probes(launch_dir, cwd)

    launch = rosl.start("launch", str(path), env=env)

    assert launch.wait_for(r"process has died \[pid \d+, exit code 3, "), launch.both()
    assert launch.wait_for(r"^\[probe-1\] to stderr$"), launch.both()
    assert launch.wait_for(r"^\[waiting-3\] waiting$"), launch.both()  # Ctrl-C is caught now
    assert launch.wait_for(r"process has finished cleanly"), launch.both()
    out = launch.lines()
    assert f"[probe-1] cwd {cwd}" in out, launch.both()
    assert "[probe-1] env hello None" in out, launch.both()  # SIGINT was let in by the entry
    assert "[probe-1] argv ['one', 'two']" in out, launch.both()
    assert "[probe-1] orig ['-P', '-m', 'rosl.pkg.entry'] ['one', 'two']" in out, launch.both()
    assert "[probe-1] leader True" in out, launch.both()
    assert "[failing-2] env None None" in out, launch.both()  # not the other node's variable
    forked = env["ROSL_LAUNCH_ZYGOTE"] == "1"
    assert (f"[probe-1] parent {launch.pid}" in out) is not forked, launch.both()
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
    assert not zygote.can_fork(entry, {**env, "LD_PRELOAD": "/lib/x.so"})
    assert not zygote.can_fork(entry, {**env, "LC_ALL": "C"})  # read when Python starts
    assert zygote.can_fork(entry, {**env, "TZ": "XYZ-3", "PROBE": "1"})  # applied in the child
    monkeypatch.setenv("ROSL_LAUNCH_ZYGOTE", "0")
    assert not zygote.can_fork(entry, env)  # switched off
    monkeypatch.delenv("ROSL_LAUNCH_ZYGOTE")
    assert zygote.can_fork(entry, env)  # the default


# --- the zygote's hazards -----------------------------------------------------------------------

SITE = """
import os
import threading
import time

with open("/proc/self/cmdline", "rb") as cmdline:
    IN_ZYGOTE = b"rosl.launch.zygote_server" in cmdline.read()
if IN_ZYGOTE and os.environ.get("SITE_THREAD"):  # as a library's thread pool would
    threading.Thread(target=time.sleep, args=(3600,), daemon=True).start()
if IN_ZYGOTE and os.environ.get("SITE_SAYS"):
    print(os.environ["SITE_SAYS"], flush=True)
"""

ONE_PROBE = """
import sys
from launch import LaunchDescription
from launch.actions import ExecuteProcess


def generate_launch_description():
    return LaunchDescription([
        ExecuteProcess(
            cmd=[sys.executable, "-P", "-m", "rosl.pkg.entry", {folder!r}, {script!r}, "probe"],
            name="probe", output="screen", additional_env={env!r},
        ),
    ])
"""


def _probe_launch(launch_dir: Path, env: dict[str, str] | None = None) -> Path:
    script = launch_dir / "probe.py"
    script.write_text(PROBE, encoding="utf-8")
    source = ONE_PROBE.format(folder=str(launch_dir), script=str(script), env=env or {})
    return write_launch(launch_dir, "one.launch.py", source)


def _finished_with_site(rosl: Rosl, launch_dir: Path, tmp_path: Path, **env: str) -> Output:
    """One probe launched with SITE (and ``env``) in every interpreter, run to its end."""
    folder = tmp_path / "site"
    folder.mkdir()
    (folder / "sitecustomize.py").write_text(SITE, encoding="utf-8")
    env.update(ROSL_LAUNCH_ZYGOTE="1", PYTHONPATH=str(folder))
    launch = rosl.start("launch", str(_probe_launch(launch_dir)), env=env)
    assert launch.finish(60.0) == 0, launch.both()
    return launch


def test_a_zygote_with_a_second_thread_forks_nothing_and_nodes_start_afresh(
    rosl: Rosl, launch_dir: Path, tmp_path: Path
) -> None:
    launch = _finished_with_site(rosl, launch_dir, tmp_path, SITE_THREAD="1")
    out = launch.lines()

    assert any("fresh interpreters: the zygote has 2 threads" in line for line in out), out
    assert f"[probe-1] parent {launch.pid}" in out, launch.both()  # started afresh
    assert "[probe-1] to stderr" in out, launch.both()


def test_the_zygotes_own_output_is_prefixed_like_the_launchers(
    rosl: Rosl, launch_dir: Path, tmp_path: Path
) -> None:
    launch = _finished_with_site(rosl, launch_dir, tmp_path, SITE_SAYS="said by site")

    assert "[INFO] [launch.zygote]: said by site" in launch.lines(), launch.both()
    assert not [line for line in launch.lines() + launch.lines("err") if not line.startswith("[")]
    assert f"[probe-1] parent {launch.pid}" not in launch.lines(), launch.both()  # forked


def test_start_up_only_variables_start_a_node_afresh_and_tz_is_applied_when_forked(
    rosl: Rosl, launch_dir: Path
) -> None:
    script = launch_dir / "probe.py"
    script.write_text(PROBE, encoding="utf-8")
    entry = [sys.executable, "-P", "-m", "rosl.pkg.entry", str(launch_dir), str(script)]
    path = write_launch(
        launch_dir,
        "env.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess


        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd={[*entry, "zone"]!r}, name="zone", output="screen",
                               additional_env={{"TZ": "XYZ-3"}}),
                ExecuteProcess(cmd={[*entry, "plain"]!r}, name="plain", output="screen",
                               additional_env={{"LC_ALL": "C"}}),
            ])
        """,
    )

    env = {"ROSL_LAUNCH_ZYGOTE": "1", "LC_ALL": "C.UTF-8", "TZ": "UTC"}
    launch = rosl.start("launch", str(path), env=env)
    code = launch.finish(60.0)
    out = launch.lines()

    assert code == 0, launch.both()
    assert f"[zone-1] parent {launch.pid}" not in out, launch.both()  # forked, TZ applied
    assert "[zone-1] zone XYZ utf8 0" in out, launch.both()
    assert f"[plain-2] parent {launch.pid}" in out, launch.both()  # the C locale: afresh
    assert "[plain-2] zone UTC utf8 1" in out, launch.both()  # Python's C-locale UTF-8 mode


def _zygote_children(launcher: int) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            cmdline = (entry / "cmdline").read_bytes()
        except (OSError, IndexError):
            continue
        if int(stat[1]) == launcher and b"rosl.launch.zygote_server" in cmdline:
            found.append(int(entry.name))
    return found


def test_a_node_outlives_a_killed_zygote_under_the_launchers_supervision(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = _probe_launch(launch_dir, {"PROBE_WAIT": "1", "PROBE_IGNORE_TERM": "1"})

    launch = rosl.start("launch", str(path), env={"ROSL_LAUNCH_ZYGOTE": "1"})
    assert launch.wait_for(r"^\[probe-1\] waiting$"), launch.both()
    [zygote_pid] = _zygote_children(launch.pid)
    os.kill(zygote_pid, signal.SIGKILL)  # the node gets its parent-death SIGTERM: ignored
    time.sleep(1.0)  # the launcher takes in the loss (and must not count the node as ended)
    [pid] = launch.pids()

    assert running(pid), launch.both()
    assert launch.interrupt() == 0, launch.both()  # Ctrl-C still reaches it, its exit is read
    assert "[probe-1] interrupted" in launch.lines(), launch.both()
    assert any("process has finished cleanly" in line for line in launch.lines()), launch.both()
    assert_all_gone([pid])  # reaped by the launcher, not left as a zombie


# --- the launcher's side, driven directly -------------------------------------------------------


def _entry(launch_dir: Path) -> list[str]:
    script = launch_dir / "probe.py"
    script.write_text(PROBE, encoding="utf-8")
    return [sys.executable, "-P", "-m", "rosl.pkg.entry", str(launch_dir), str(script), "probe"]


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return "gone"


def test_an_ended_node_is_not_reaped_before_the_launcher_has_read_its_exit(
    launch_dir: Path, domain_id: int
) -> None:
    from rosl.launch.zygote import Zygote

    zygote = Zygote()
    try:
        process = zygote.spawn(_entry(launch_dir), {**os.environ, "PROBE_EXIT": "3"}, None, False)
        assert wait_until(lambda: _state(process.pid) == "Z", 60.0), _state(process.pid)
        time.sleep(0.5)
        assert _state(process.pid) == "Z"  # its pid stays taken: a signal cannot go astray
        process.send_signal(signal.SIGTERM)  # to an ended node: nothing is sent, no error
        assert process.wait(30.0) == 3
        assert wait_until(lambda: _state(process.pid) == "gone", 30.0)  # reaped once read
    finally:
        zygote.close()


def test_a_zygote_that_does_not_answer_in_time_leaves_its_nodes_running(
    launch_dir: Path, domain_id: int
) -> None:
    from rosl.launch.zygote import Zygote, ZygoteError

    entry = _entry(launch_dir)
    waiting = {**os.environ, "PROBE_WAIT": "1"}
    zygote = Zygote()
    try:
        first = zygote.spawn(entry, waiting, None, False)
        os.kill(zygote.popen.pid, signal.SIGSTOP)
        zygote.answer_timeout = 1.0
        with pytest.raises(ZygoteError, match="does not answer"):
            zygote.spawn(entry, waiting, None, False)
        os.kill(zygote.popen.pid, signal.SIGCONT)
        assert wait_until(lambda: (zygote.collect(0.1), zygote.strays)[1], 30.0)
        [stray] = zygote.strays  # forked after the launcher gave up: ended at once
        assert wait_until(lambda: (zygote.collect(0.1), _state(stray) == "gone")[1], 30.0)
        assert first.poll() is None  # the node started before runs on
        first.send_signal(signal.SIGINT)
        assert first.wait(30.0) == 0
    finally:
        zygote.close()


def test_a_zygote_not_ready_in_time_forks_nothing(launch_dir: Path, domain_id: int) -> None:
    from rosl.launch.zygote import Zygote, ZygoteError

    zygote = Zygote()
    try:
        os.kill(zygote.popen.pid, signal.SIGSTOP)  # still warming up
        zygote.ready_timeout = 1.0
        with pytest.raises(ZygoteError, match="is not ready"):
            zygote.spawn(_entry(launch_dir), dict(os.environ), None, False)
        os.kill(zygote.popen.pid, signal.SIGCONT)
    finally:
        zygote.close()
    assert zygote.popen.returncode is not None


@pytest.mark.parametrize("env", MODES)
def test_a_missing_working_folder_is_one_line_naming_it(
    rosl: Rosl, launch_dir: Path, tmp_path: Path, env: dict[str, str]
) -> None:
    missing = tmp_path / "no such folder"
    path = _three_probes(launch_dir, missing)

    launch = rosl.start("launch", str(path), env=env)
    assert launch.wait_for(r"^\[waiting-3\] waiting$"), launch.both()  # the others start
    assert launch.interrupt() == 1, launch.both()

    err = launch.text("err") + launch.text("out")
    assert f"[ERROR] [probe-1]: cannot start {sys.executable} in {missing} (cwd): " in err, err
    assert "Traceback" not in err, err
    assert "[probe-1] cwd" not in err, err


def _zombie_children(launcher: int) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        try:
            stat = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if stat[0] == "Z" and int(stat[1]) == launcher:
            found.append(int(entry.name))
    return found


def test_processes_left_behind_by_a_launched_shell_are_reaped_not_kept_as_zombies(
    rosl: Rosl, launch_dir: Path
) -> None:
    # the launcher inherits orphans (a subreaper, for the zygote's nodes); ended ones go
    path = write_launch(
        launch_dir,
        "orphans.launch.py",
        f"""
        import sys
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess

        ENTRY = [sys.executable, "-P", "-m", "rosl.pkg.entry", {str(launch_dir)!r}]


        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd=[*ENTRY, {str(launch_dir / "probe.py")!r}, "waiting"],
                               output="screen", additional_env={{"PROBE_WAIT": "1"}}),
                ExecuteProcess(cmd=["sh", "-c", "(sleep 0.2 &); (sleep 0.2 &); echo left"],
                               output="screen"),
            ])
        """,
    )
    (launch_dir / "probe.py").write_text(PROBE, encoding="utf-8")

    launch = rosl.start("launch", str(path), env={"ROSL_LAUNCH_ZYGOTE": "1"})
    assert launch.wait_for(r"^\[python-1\] waiting$"), launch.both()
    assert launch.wait_for(r"^\[sh-2\] left$"), launch.both()
    assert launch.wait_for(r"\[sh-2\]: process has finished cleanly"), launch.both()
    assert len(_zygote_children(launch.pid)) == 1  # the subreaper's reason is there

    assert wait_until(lambda: not _zombie_children(launch.pid), 30.0), _zombie_children(launch.pid)
    assert launch.interrupt() == 0, launch.both()


@pytest.mark.parametrize("env", MODES)
def test_a_node_shows_its_own_command_line_and_name(
    rosl: Rosl, launch_dir: Path, env: dict[str, str]
) -> None:
    launch = rosl.start("launch", str(_probe_launch(launch_dir, {"PROBE_WAIT": "1"})), env=env)
    assert launch.wait_for(r"^\[probe-1\] waiting$"), launch.both()
    [pid] = launch.pids()
    shown = Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode().strip()
    name = Path(f"/proc/{pid}/comm").read_text().strip()
    assert launch.interrupt() == 0, launch.both()

    assert shown.startswith(f"{sys.executable} -P -m rosl.pkg.entry {launch_dir} "), shown
    assert shown.endswith(" probe"), shown  # what ps and pgrep -f show, forked or not
    assert name == Path(sys.executable).name[:15]


IN_PROCESS = """
import ctypes
import os
import sys

import rosl  # noqa: F401 - the launch package's alias
from launch import LaunchDescription, LaunchService
from launch.actions import ExecuteProcess

prctl = ctypes.CDLL(None, use_errno=True).prctl
flag = ctypes.c_int(-1)
service = LaunchService()
service.include_launch_description(LaunchDescription([
    ExecuteProcess(cmd=sys.argv[1:], name="probe", output="screen"),
]))
print("launcher", os.getpid(), flush=True)
print("launch exit", service.run(), flush=True)
prctl(37, ctypes.byref(flag))  # PR_GET_CHILD_SUBREAPER
print("subreaper after", flag.value, flush=True)
"""


def test_an_in_process_launch_leaves_its_process_no_subreaper(
    processes: Processes, launch_dir: Path, domain_id: int
) -> None:
    # a launch forking nodes makes its process a subreaper (a lost zygote's nodes come to
    # it); a program that ran a launch in-process goes on without inheriting orphans
    child = processes.python(IN_PROCESS, *_entry(launch_dir), env={"ROSL_LAUNCH_ZYGOTE": "1"})
    out, err = child.communicate(timeout=120)
    assert child.returncode == 0, err
    assert "launch exit 0" in out, out + err
    launcher = out.split("launcher ", 1)[1].split()[0]
    parent = out.split("[probe-1] parent ", 1)[1].split()[0]
    assert parent != launcher, out  # forked from the zygote: the flag was set
    assert "subreaper after 0" in out, out + err
