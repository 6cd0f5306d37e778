"""Supervision: exit lines, escalation SIGINT → SIGTERM → SIGKILL, and no orphans however the
launcher is stopped (Ctrl-C, SIGTERM, SIGKILL)."""

from __future__ import annotations

import os
import pty
import re
import select
import signal
import subprocess
import sys
import time
from typing import TYPE_CHECKING

import pytest

from tests.launch.support import ANSI, PYTHON, STARTED, assert_all_gone, write_launch

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Rosl

SLEEPER = "import time; print('ready', flush=True); time.sleep(60)"
IGNORES_SIGINT = (
    "import signal, time; signal.signal(signal.SIGINT, signal.SIG_IGN); "
    "print('ready', flush=True); time.sleep(60)"
)
IGNORES_SIGINT_AND_SIGTERM = (
    "import signal, time; signal.signal(signal.SIGINT, signal.SIG_IGN); "
    "signal.signal(signal.SIGTERM, signal.SIG_IGN); print('ready', flush=True); time.sleep(60)"
)


def processes_launch(launch_dir: Path, name: str, programs: dict[str, str]) -> Path:
    """A launch file with one ExecuteProcess (output='screen') per ``name: python code``."""
    entries = "\n".join(
        f"        ExecuteProcess(cmd=[{PYTHON!r}, '-c', {code!r}], name={label!r}, "
        "output='screen'),"
        for label, code in programs.items()
    )
    return write_launch(
        launch_dir,
        name,
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n\n\n"
        "def generate_launch_description():\n"
        f"    return LaunchDescription([\n{entries}\n    ])\n",
    )


def test_a_process_that_fails_at_once_is_reported_as_died_and_fails_the_launch(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = processes_launch(launch_dir, "dies.launch.py", {"x": "import sys; sys.exit(2)"})

    launch = rosl.start("launch", str(path))

    assert launch.finish() not in (0, None), launch.both()
    [pid] = launch.started()["x-1"]
    expected = (
        f"[ERROR] [x-1]: process has died [pid {pid}, exit code 2, "
        f"cmd '{PYTHON} -c import sys; sys.exit(2)']."
    )
    assert expected in launch.lines(), launch.both()
    assert "Traceback" not in launch.text("err")
    assert_all_gone([pid])


def test_a_process_that_finishes_cleanly_does_not_fail_the_launch(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = processes_launch(launch_dir, "finishes.launch.py", {"ok": "pass"})

    launch = rosl.start("launch", str(path))

    assert launch.finish() == 0, launch.both()
    [pid] = launch.started()["ok-1"]
    assert f"[INFO] [ok-1]: process has finished cleanly [pid {pid}]" in launch.lines()


def test_ctrl_c_escalates_to_sigterm_and_sigkill_for_processes_that_ignore_it(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = processes_launch(
        launch_dir,
        "stubborn.launch.py",
        {"stubborn": IGNORES_SIGINT, "very_stubborn": IGNORES_SIGINT_AND_SIGTERM},
    )

    launch = rosl.start("launch", str(path), "sigterm_timeout:=1", "sigkill_timeout:=1")
    assert launch.wait_for(r"^\[(very_)?stubborn-\d\] ready$", count=2), launch.both()
    pids = launch.pids()

    assert launch.interrupt(timeout=30.0) == 0, launch.both()

    def escalation(label: str, received: str, following: str) -> str:
        # launch prints the SIGTERM timeout as given, and for SIGKILL the time since SIGINT
        # (both timeouts added up by a PythonExpression, hence a float)
        seconds = "1" if received == "SIGINT" else r"2\.0"
        return (
            rf"^\[ERROR\] \[{label}\]: process\[{label}\] failed to terminate '{seconds}' "
            rf"seconds after receiving '{received}', escalating to '{following}'$"
        )

    assert launch.matching(escalation("stubborn-1", "SIGINT", "SIGTERM")), launch.both()
    assert launch.matching(escalation("very_stubborn-2", "SIGINT", "SIGTERM")), launch.both()
    assert launch.matching(escalation("very_stubborn-2", "SIGTERM", "SIGKILL")), launch.both()
    assert not launch.matching(escalation("stubborn-1", "SIGTERM", "SIGKILL")), launch.both()
    assert launch.matching(r"^\[ERROR\] \[stubborn-1\]: process has died \[pid \d+, exit code -15,")
    assert launch.matching(
        r"^\[ERROR\] \[very_stubborn-2\]: process has died \[pid \d+, exit code -9,"
    )
    assert_all_gone(pids)


@pytest.mark.slow
def test_ctrl_c_stops_a_launch_of_twenty_nodes_leaving_no_process(
    rosl: Rosl, launch_dir: Path
) -> None:
    nodes = "\n".join(
        f"        Node(package='tutorial_pkg', executable='my_publisher', name='pub_{i:02d}', "
        "output='screen'),"
        for i in range(20)
    )
    path = write_launch(
        launch_dir,
        "twenty.launch.py",
        "from launch import LaunchDescription\n"
        "from launch_ros.actions import Node\n\n\n"
        "def generate_launch_description():\n"
        f"    return LaunchDescription([\n{nodes}\n    ])\n",
    )

    launch = rosl.start("launch", str(path))
    assert launch.wait_for(r"process started with pid", count=20, timeout=60.0), launch.both()
    # every node is up and spinning (its first publication) before the Ctrl-C
    assert launch.wait_for(r"\[pub_\d\d\]: Publishing: counter=1 ", count=20, timeout=120.0), (
        launch.both()
    )
    pids = launch.pids()
    assert len(set(pids)) == 20

    assert launch.interrupt(timeout=60.0) == 0, launch.both()

    assert (
        len(launch.matching(r"^\[INFO\] \[my_publisher-\d+\]: process has finished cleanly")) == 20
    )
    assert_all_gone(pids)


def test_sigterm_to_the_launcher_stops_its_children(rosl: Rosl, launch_dir: Path) -> None:
    path = processes_launch(launch_dir, "sigterm.launch.py", {"a": SLEEPER, "b": SLEEPER})

    launch = rosl.start("launch", str(path))
    assert launch.wait_for(r"^\[[ab]-\d\] ready$", count=2), launch.both()
    pids = launch.pids()

    assert launch.interrupt(signal.SIGTERM) is not None, launch.both()

    assert launch.matching(r"\[a-1\]: process has (finished cleanly|died)"), launch.both()
    assert launch.matching(r"\[b-2\]: process has (finished cleanly|died)"), launch.both()
    assert_all_gone(pids)


def test_sigkill_to_the_launcher_takes_its_children_down_too(rosl: Rosl, launch_dir: Path) -> None:
    path = write_launch(
        launch_dir,
        "sigkill.launch.py",
        f"""
        from launch import LaunchDescription
        from launch.actions import ExecuteProcess
        from launch_ros.actions import Node


        def generate_launch_description():
            return LaunchDescription([
                ExecuteProcess(cmd=[{PYTHON!r}, "-c", {SLEEPER!r}], name="sleeper",
                               output="screen"),
                Node(package="tutorial_pkg", executable="my_publisher", output="screen"),
            ])
        """,
    )

    launch = rosl.start("launch", str(path))
    assert launch.wait_for(r"^\[sleeper-1\] ready$"), launch.both()
    assert launch.wait_for(r"\[my_publisher\]: Publishing: counter=1 "), launch.both()
    pids = launch.pids()
    assert len(pids) == 2

    os.kill(launch.pid, signal.SIGKILL)

    assert launch.finish() == -signal.SIGKILL
    # nobody is left to reap them: an exited (zombie) child counts as gone
    assert_all_gone(pids, timeout=15.0, allow_unreaped=True)


def test_launcher_output_is_plain_when_piped(rosl: Rosl, launch_dir: Path) -> None:
    path = processes_launch(launch_dir, "plain.launch.py", {"talker": "print('hello')"})

    launch = rosl.start("launch", str(path))

    assert launch.finish() == 0, launch.both()
    assert "[talker-1] hello" in launch.lines()
    assert not re.search(r"\x1b\[", launch.text("out") + launch.text("err"))


def run_on_a_terminal(path: Path, env: dict[str, str], timeout: float = 60.0) -> str:
    """Run ``rosl launch PATH`` with a pseudo-terminal as stdout/stderr; return what it wrote."""
    master, slave = pty.openpty()
    child = subprocess.Popen(
        [sys.executable, "-m", "rosl", "launch", str(path)],
        stdin=subprocess.DEVNULL, stdout=slave, stderr=slave, env=env, start_new_session=True,
    )  # fmt: skip
    os.close(slave)
    data = b""
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline:
            ready, _, _ = select.select([master], [], [], 0.2)
            if ready:
                try:
                    chunk = os.read(master, 65536)
                except OSError:  # EIO: the terminal's other side is closed
                    break
                if not chunk:
                    break
                data += chunk
        assert child.wait(timeout=max(0.1, deadline - time.monotonic())) == 0, data
    finally:
        os.close(master)
        if child.poll() is None:
            child.kill()
            child.wait(timeout=5)
    return data.decode("utf-8", "replace").replace("\r\n", "\n")


def test_on_a_terminal_prefixes_are_coloured_unless_no_color_is_set(
    launch_dir: Path, log_dir: Path, domain_id: int
) -> None:
    path = processes_launch(launch_dir, "tty.launch.py", {"talker": "print('hello')"})
    env = {k: v for k, v in os.environ.items() if k != "NO_COLOR"}

    coloured = run_on_a_terminal(path, env)
    plain = run_on_a_terminal(path, {**env, "NO_COLOR": "1"})

    assert re.search(r"^\x1b\[[0-9;]*m\[talker-1\]\x1b\[0m hello$", coloured, re.MULTILINE), (
        coloured
    )
    assert "[talker-1] hello" in plain.splitlines(), plain
    assert not ANSI.search(plain), plain
    pids = [int(m["pid"]) for m in map(STARTED.match, (coloured + plain).splitlines()) if m]
    assert len(pids) == 2
    assert_all_gone(pids)


def test_every_line_of_a_fast_talker_arrives_whole_and_in_order(
    rosl: Rosl, launch_dir: Path
) -> None:
    path = processes_launch(
        launch_dir,
        "burst.launch.py",
        {
            "out": (
                "import sys\n"
                "for i in range(5000): print(f'line {i}')\n"
                "print('x' * 100000)\n"
                "sys.stdout.write('last words without a newline')"
            ),
            "err": "import sys\nfor i in range(5000): print(f'err {i}', file=sys.stderr)",
        },
    )

    launch = rosl.start("launch", str(path))

    assert launch.finish(timeout=30.0) == 0, launch.text("err")
    lines = launch.lines()
    assert [line for line in lines if line.startswith("[out-1] line ")] == [
        f"[out-1] line {i}" for i in range(5000)
    ]
    assert [line for line in lines if line.startswith("[err-2] ")] == [
        f"[err-2] err {i}" for i in range(5000)
    ]
    assert "[out-1] " + "x" * 100000 in lines
    assert "[out-1] last words without a newline" in lines
    assert_all_gone(launch.pids())
