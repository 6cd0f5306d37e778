"""One Ctrl-C ends a launch at any moment: quickly, with no traceback and no process left.

The seed's launch file (three Python nodes) gets one SIGINT at several moments of its start:
as soon as the launcher speaks, just after a node was started (its interpreter still starting),
a little later, and once every node is up. The same holds when the launcher was started as a
shell starts a background job, with SIGINT ignored: it takes SIGINT anyway. (A SIGINT while
the launcher's own interpreter starts, before any rosl code runs, is Python's to handle.)
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.launch.support import Output, assert_all_gone, write_launch

if TYPE_CHECKING:
    from tests.conftest import Processes
    from tests.launch.support import Rosl

EXIT_BOUND_S = 30.0  # generous: a clean stop takes well under a second
FIRST_LINE = r"^\[INFO\] \[launch\]: All log files can be found below "
STARTED = r"process started with pid"
# A Ctrl-C before the launch file was loaded and processed exits 130 (the launch never got
# under way); once the launch runs, its clean stop exits 0, as ros2 launch's does. Near the
# end of the processing either can happen, depending on when the SIGINT lands.
LOADING, RUNNING, EITHER = (130,), (0,), (0, 130)
MOMENTS = {
    "at the first line": (FIRST_LINE, 1, 0.0, LOADING),
    "as the first node starts": (STARTED, 1, 0.0, LOADING),
    "as the last node starts": (STARTED, 3, 0.0, EITHER),
    "a moment later": (FIRST_LINE, 1, 0.2, EITHER),
    "once every node is up": (r"\[timer_node\]: Timer period: 1\.5 s$", 1, 0.0, RUNNING),
}


def start_launch(
    rosl: Rosl, *, sigint_ignored: bool, target: tuple[str, ...] = ("tutorial_pkg", "my_launch.py")
) -> Output:
    """``rosl launch tutorial_pkg my_launch.py``, with SIGINT ignored as in a background job."""
    if not sigint_ignored:
        return rosl.start("launch", *target)

    def ignore_sigint() -> None:  # what a shell does for `rosl launch ... &`
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    child = subprocess.Popen(
        [sys.executable, "-m", "rosl", "launch", *target],
        env={**os.environ, "PYTHONUNBUFFERED": "1"}, stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        preexec_fn=ignore_sigint,
    )  # fmt: skip
    rosl.processes.started.append(child)  # ended by pid by the processes fixture
    output = Output(child)
    rosl.watched.append(output)  # its nodes too, should the test fail
    return output


@pytest.mark.parametrize("sigint_ignored", [False, True], ids=["foreground", "background"])
@pytest.mark.parametrize("moment", list(MOMENTS))
def test_one_sigint_ends_the_launch_cleanly_at_any_moment(
    rosl: Rosl, moment: str, sigint_ignored: bool
) -> None:
    pattern, count, later, codes = MOMENTS[moment]
    launch = start_launch(rosl, sigint_ignored=sigint_ignored)
    assert launch.wait_for(pattern, count=count, timeout=30.0), launch.both()
    if later:
        time.sleep(later)

    code = launch.interrupt(signal.SIGINT, timeout=EXIT_BOUND_S)  # once

    assert code in codes, f"exit {code} after one SIGINT\n{launch.both()}"
    text = launch.text("out") + launch.text("err")
    assert "Traceback" not in text, launch.both()
    assert "Fatal Python error" not in text, launch.both()
    assert launch.matching(r"^\[WARNING\] \[launch\]: user interrupted with ctrl-c \(SIGINT\)$")
    pids = launch.pids()
    if pids:  # at the first line nothing has started yet, and nothing starts after the Ctrl-C
        assert_all_gone(pids)
        for label in launch.started():
            assert launch.matching(rf"^\[(INFO|ERROR)\] \[{label}\]: process has "), launch.both()


SLOW_LAUNCH = """
import sys
import time

from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    print("loading the slow launch file", flush=True)
    time.sleep(30.0)  # bounded: far longer than the test waits for the exit
    return LaunchDescription([Node(package="tutorial_pkg", executable="timer_node")])
"""
LOADING_EXIT_BOUND_S = 10.0  # well under the launch file's 30 s sleep


@pytest.mark.parametrize("sigint_ignored", [False, True], ids=["foreground", "background"])
def test_one_sigint_ends_the_launch_while_its_file_loads(
    rosl: Rosl, launch_dir: Path, sigint_ignored: bool
) -> None:
    path = write_launch(launch_dir, "slow.launch.py", SLOW_LAUNCH)
    launch = start_launch(rosl, sigint_ignored=sigint_ignored, target=(str(path),))
    assert launch.wait_for(r"^loading the slow launch file$", timeout=30.0), launch.both()

    code = launch.interrupt(signal.SIGINT, timeout=LOADING_EXIT_BOUND_S)  # once

    assert code is not None, f"still running {LOADING_EXIT_BOUND_S} s after one SIGINT"
    assert code == 130, f"exit {code} after one SIGINT while loading\n{launch.both()}"
    text = launch.text("out") + launch.text("err")
    assert "Traceback" not in text, launch.both()
    assert launch.matching(r"^\[WARNING\] \[launch\]: user interrupted with ctrl-c \(SIGINT\)$")
    assert not launch.pids(), launch.both()  # nothing starts after the Ctrl-C


def node_interpreter_starting(pid: int, *, catching: bool, timeout: float = 30.0) -> bool:
    """Wait until ``rosl run`` has become the node (and, if ``catching``, it catches SIGINT).

    Right after the exec a SIGINT ignored by the shell would be lost; once Python has
    installed its Ctrl-C handler it imports site, then the node's modules, and a SIGINT that
    got in then would end it with a traceback.
    """
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            cmdline = Path(f"/proc/{pid}/cmdline").read_bytes()
            status = Path(f"/proc/{pid}/status").read_text()
        except OSError:
            return False
        caught = int(status.split("SigCgt:")[1].split()[0], 16)
        if b"rosl.pkg.entry" in cmdline and (caught & (1 << (signal.SIGINT - 1)) or not catching):
            return True
        time.sleep(0.001)
    return False


@pytest.mark.parametrize("sigint_ignored", [False, True], ids=["foreground", "background"])
def test_a_sigint_while_the_run_node_starts_ends_it_quietly(
    processes: Processes, log_dir: Path, sigint_ignored: bool
) -> None:
    def ignore_sigint() -> None:
        if sigint_ignored:
            signal.signal(signal.SIGINT, signal.SIG_IGN)

    child = subprocess.Popen(
        [sys.executable, "-m", "rosl", "run", "tutorial_pkg", "timer_node"],
        env={**os.environ, "PYTHONUNBUFFERED": "1"}, stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        preexec_fn=ignore_sigint,
    )  # fmt: skip
    processes.started.append(child)
    assert node_interpreter_starting(child.pid, catching=not sigint_ignored), child.poll()

    child.send_signal(signal.SIGINT)  # its interpreter is starting: the SIGINT waits for it
    try:
        _, err = child.communicate(timeout=EXIT_BOUND_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"rosl run still running {EXIT_BOUND_S} s after one SIGINT")
    # 130: stopped before rosl.init; 0: just after it (a clean shutdown); -2: Python's own
    # exit for a KeyboardInterrupt that crossed an exec() of a string while modules loaded
    assert child.returncode in (0, 130, -signal.SIGINT), (child.returncode, err)
    assert "Traceback" not in err, err
    assert "Fatal Python error" not in err, err


def test_a_closed_output_pipe_ends_the_launch_as_a_ctrl_c_does(rosl: Rosl) -> None:
    """``rosl launch ... | head -3``: once head is gone, the launch stops its nodes and exits."""
    child = subprocess.Popen(
        [sys.executable, "-m", "rosl", "launch", "tutorial_pkg", "my_launch.py"],
        env={**os.environ, "PYTHONUNBUFFERED": "1"}, stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
    )  # fmt: skip
    rosl.processes.started.append(child)  # ended by pid by the processes fixture
    assert child.stdout is not None
    assert child.stderr is not None
    pids: list[int] = []
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:  # as head does: read until every node is up
        line = child.stdout.readline().decode()
        pids += [int(p) for p in re.findall(r"process started with pid \[(\d+)\]", line)]
        if not line or re.search(r"\[timer_node\]: Timer period: 1\.5 s$", line):
            break
    assert len(pids) == 3, pids
    child.stdout.close()  # head exits: the launcher's next line meets a closed pipe

    try:
        code = child.wait(timeout=EXIT_BOUND_S)  # timer_node prints every 1.5 s
    except subprocess.TimeoutExpired:
        pytest.fail(f"still running {EXIT_BOUND_S} s after its output pipe closed")
    err = child.stderr.read().decode()
    assert code == 0, f"exit {code} after its output pipe closed\n{err}"
    assert "Traceback" not in err, err
    assert "Exception ignored" not in err, err
    assert_all_gone(pids)
