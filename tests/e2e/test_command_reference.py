"""The first seed's "Full Command Reference", ``ros2`` replaced by ``rosl``, on the real system.

Each command is typed as the seed types it (only the picture folder is ours), run as a real
process on this test's domain, and checked against what ROS 2 prints or does: the interface
text, the service reply, the timer really ticking faster after ``param set``, the robot's pose
on ``/odom``, and view_frames' TurtleBot3 tree in frames.gv and frames.pdf.
"""

from __future__ import annotations

import contextlib
import itertools
import os
import re
import shlex
import signal
import subprocess
import sys
import time
from typing import TYPE_CHECKING

import pytest
import yaml

from tests.conftest import REPO, wait_until
from tests.graph.support import Watched

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.node.node import Node
    from tests.conftest import Processes

SEED_PICTURES = "/home/sandip/Pictures"
REFERENCE = {  # the seed's lines (the service call joined from its two lines)
    "interface": "ros2 interface show tutorial_pkg/msg/MyData",
    "service": "ros2 service call /count_images tutorial_pkg/srv/CountImages "
    f"\"{{folder_path: '{SEED_PICTURES}'}}\"",
    "param": "ros2 param set /timer_node timer_period_s 0.5",
    "launch": "ros2 launch tutorial_pkg my_launch.py",
    "echo": "ros2 topic echo /odom --once",
    "frames": "ros2 run tf2_tools view_frames",
}
TICK = r"^\[timer_node-3\] \[INFO\] \[(\d+\.\d+)\] \[timer_node\]: Tick \d+ \(period 0\.5 s\)$"
CHANGED = (
    r"^\[timer_node-3\] \[INFO\] \[(\d+\.\d+)\] \[timer_node\]: Timer period changed to 0\.5 s$"
)
STARTED = re.compile(r"^\[INFO\] \[[^\]]+\]: process started with pid \[(\d+)\]$")
TURTLEBOT3_EDGES = [
    ("odom", "base_footprint"),
    ("base_footprint", "base_link"),
    ("base_link", "base_scan"),
    ("base_link", "imu_link"),
    ("base_link", "wheel_left_link"),
    ("base_link", "wheel_right_link"),
]


def rosl_words(line: str, pictures: Path | None = None) -> list[str]:
    """A seed line as an argv for this interpreter's rosl (``ros2`` → ``rosl``)."""
    if pictures is not None:
        line = line.replace(SEED_PICTURES, str(pictures))
    words = shlex.split(line)
    assert words[0] == "ros2", line
    return [sys.executable, "-m", "rosl", *words[1:]]


def run(processes: Processes, line: str, pictures: Path | None = None) -> tuple[int, str, str]:
    """Run one seed line to its end (bounded); (exit code, stdout, stderr)."""
    child = processes.start(rosl_words(line, pictures), env={"NO_COLOR": "1"})
    out, err = child.communicate(timeout=60)
    return child.returncode, out, err


def background(processes: Processes, words: list[str], **kwargs: object) -> Watched:
    return Watched(processes.start(words, env={"NO_COLOR": "1"}, **kwargs))  # type: ignore[arg-type]


def end(child: Watched, *, group: bool = False) -> int | None:
    """Ctrl-C a background command (its whole group, as a terminal does) and wait."""
    if child.child.poll() is None:
        if group:
            os.killpg(child.pid, signal.SIGINT)
            child.signalled = True
        else:
            child.send()
    return child.interrupt(timeout=15.0)


def end_launched(launch: Watched) -> None:
    """After a launcher that did not stop cleanly: end what it started, by pid."""
    for line in launch.lines():
        match = STARTED.match(line)
        if match:
            with contextlib.suppress(ProcessLookupError):
                os.kill(int(match[1]), signal.SIGKILL)


@pytest.mark.slow
def test_the_seeds_full_command_reference_runs_with_rosl(
    processes: Processes, observer_node: Node, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROSL_LOG_DIR", str(tmp_path / "log"))
    pictures = tmp_path / "Pictures"
    pictures.mkdir()
    for name in ("a.png", "b.jpg", "c.jpeg", "notes.txt"):
        (pictures / name).write_bytes(b"x")
    frames_dir = tmp_path / "frames"
    frames_dir.mkdir()

    # the background: the simulated TurtleBot3, the seed's launch file, the image counter
    sim = background(processes, [sys.executable, "-m", "rosl", "sim", "turtlebot3_world"])
    launch = background(processes, rosl_words(REFERENCE["launch"]))
    counter = background(processes, rosl_words("ros2 run tutorial_pkg count_images"))
    background_commands = {"launch": launch, "count_images": counter, "sim": sim}
    try:
        check_commands(processes, observer_node, launch, pictures, frames_dir)
    finally:
        codes = {
            name: end(child, group=child is launch) for name, child in background_commands.items()
        }
        if codes["launch"] != 0:
            end_launched(launch)
    for name, child in background_commands.items():  # each stopped cleanly on Ctrl-C
        output = child.text("out") + child.text("err")
        assert codes[name] == 0, f"{name} exit {codes[name]}\n{output}"
        assert "Traceback" not in output, output


def check_commands(
    processes: Processes, observer: Node, launch: Watched, pictures: Path, frames_dir: Path
) -> None:
    # interface show: the message definition, as written
    code, out, err = run(processes, REFERENCE["interface"])
    assert (code, err) == (0, "")
    assert out == (REPO / "examples/tutorial_pkg/msg/MyData.msg").read_text()

    # view_frames listens for 5 s: start it as soon as the simulator broadcasts TF
    assert wait_until(lambda: observer.count_publishers("/tf") > 0, timeout=60.0), "no /tf"
    frames = background(processes, rosl_words(REFERENCE["frames"]), cwd=frames_dir)

    # service call: ros2's requester/response text
    assert wait_until(lambda: observer.wait_for_node("/count_images", 0.1), timeout=60.0)
    code, out, err = run(processes, REFERENCE["service"], pictures)
    assert (code, err) == (0, ""), out
    assert out == (
        f"requester: making request: tutorial_pkg.srv.CountImages_Request("
        f"folder_path='{pictures}')\n\nresponse:\ntutorial_pkg.srv.CountImages_Response("
        f"count=3, message='3 image(s) in {pictures}')\n\n"
    )

    # param set: the launch file's 1.5 s timer now ticks every 0.5 s, counted from the change
    assert launch.wait_for(r"\[timer_node\]: Timer period: 1\.5 s$", timeout=60.0), launch.text()
    asked = time.time()  # before the change (the log stamps are this system clock too)
    assert run(processes, REFERENCE["param"]) == (0, "Set parameter successful\n", "")
    assert launch.wait_for(CHANGED, timeout=15.0), launch.text()
    assert launch.wait_for(TICK, timeout=60.0, count=9), launch.text()
    stamps = [float(m[1]) for m in launch.matching(TICK)[:9]]
    since = [stamp - asked for stamp in stamps]
    # a tick is never early: the k-th comes at least k new periods after the change; late
    # ticks (a loaded machine) cannot break this
    assert all(s >= 0.5 * k for k, s in enumerate(since, 1)), since
    # and faster than before: at the old 1.5 s period a gap shorter than 1 s needs a late tick
    # followed by one on time; at 0.5 s most gaps are one period
    gaps = sorted(b - a for a, b in itertools.pairwise(stamps))
    assert gaps[len(gaps) // 2] < 1.0, gaps

    # topic echo --once: the robot has not turned, so its orientation is the identity
    assert wait_until(lambda: observer.count_publishers("/odom") > 0, timeout=60.0)
    code, out, err = run(processes, REFERENCE["echo"])
    assert (code, err) == (0, "")
    assert out.endswith("\n---\n")
    odom = yaml.safe_load(out.removesuffix("---\n"))
    assert (odom["header"]["frame_id"], odom["child_frame_id"]) == ("odom", "base_footprint")
    assert odom["pose"]["pose"]["orientation"]["w"] == pytest.approx(1.0, abs=1e-3)

    # view_frames: frames.gv holds the TurtleBot3 tree, frames.pdf is a PDF
    try:
        assert frames.child.wait(timeout=60.0) == 0, frames.text("err")
    except subprocess.TimeoutExpired:
        pytest.fail(f"view_frames still running\n{frames.text()}")
    dot = (frames_dir / "frames.gv").read_text()
    for parent, child in TURTLEBOT3_EDGES:
        assert f'"{parent}" -> "{child}"[label=" Broadcaster: ' in dot, dot
    assert (frames_dir / "frames.pdf").read_bytes().startswith(b"%PDF")
