"""``rosl tf frames`` and ``rosl tf echo`` against a TurtleBot-like TF broadcaster."""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.cli.conftest import Result, assert_user_error
from tests.graph.support import Watched

if TYPE_CHECKING:
    from collections.abc import Callable

    from tests.conftest import Processes

ODOM_XY = (1.0, 2.0)
ODOM_YAW = math.pi / 2
STATIC = {  # child: (parent, translation)
    "base_link": ("base_footprint", (0.0, 0.0, 0.010)),
    "base_scan": ("base_link", (-0.032, 0.0, 0.172)),
    "imu_link": ("base_link", (-0.032, 0.0, 0.068)),
    "wheel_left_link": ("base_link", (0.0, 0.08, 0.023)),
    "wheel_right_link": ("base_link", (0.0, -0.08, 0.023)),
}

BROADCASTER = f"""
import math
import time

import rosl
from geometry_msgs.msg import TransformStamped
from rosl.node.qos import DurabilityPolicy, QoSProfile
from tf2_msgs.msg import TFMessage

STATIC = {STATIC!r}
X, Y, YAW = {ODOM_XY[0]!r}, {ODOM_XY[1]!r}, {ODOM_YAW!r}


def stamped(parent, child, xyz, q=(0.0, 0.0, 0.0, 1.0)):
    t = TransformStamped()
    t.header.frame_id, t.child_frame_id = parent, child
    t.header.stamp.sec, t.header.stamp.nanosec = divmod(time.time_ns(), 10**9)
    (t.transform.translation.x, t.transform.translation.y, t.transform.translation.z) = xyz
    r = t.transform.rotation
    r.x, r.y, r.z, r.w = q
    return t


rosl.init([])
state = rosl.Node("robot_state_publisher")
odom = rosl.Node("odometry")
latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
static_pub = state.create_publisher(TFMessage, "/tf_static", latched)
static_pub.publish(TFMessage(transforms=[stamped(p, c, xyz) for c, (p, xyz) in STATIC.items()]))
tf_pub = odom.create_publisher(TFMessage, "/tf", 10)
turn = (0.0, 0.0, math.sin(YAW / 2), math.cos(YAW / 2))
odom.create_timer(0.05, lambda: tf_pub.publish(
    TFMessage(transforms=[stamped("odom", "base_footprint", (X, Y, 0.0), turn)])))
executor = rosl.get_global_executor()
executor.add_node(state)
executor.add_node(odom)
print("ready", flush=True)
executor.spin()
rosl.shutdown()
"""


def run(processes: Processes, *args: str, timeout: float = 30.0) -> Result:
    child = processes.rosl(*args, env={"NO_COLOR": "1"})
    out, err = child.communicate(timeout=timeout)
    return Result(child.returncode, out, err)


@pytest.fixture
def robot(processes: Processes) -> Watched:
    """The broadcaster, with /tf_static published once, before any CLI starts."""
    child = Watched(processes.python(BROADCASTER))
    child.wait_ready()
    return child


def test_frames_prints_the_whole_tree_from_odom_with_static_edges_marked(robot, processes) -> None:
    result = run(processes, "tf", "frames", "-t", "1.0")
    assert result.code == 0, result.err
    lines = result.out.splitlines()
    assert lines[0] == "odom"
    assert lines[1].startswith("  base_footprint  (broadcaster: /odometry, average rate: ")
    assert lines[1].endswith(" Hz)")
    # 20 Hz, timed by receive times over 1 s: a loaded machine bunches or spreads them, so
    # only a wide band (a wrong unit or count leaves it)
    assert 1.0 < float(lines[1].split("average rate: ")[1].split()[0]) < 1000.0
    assert lines[2] == "    base_link  (broadcaster: /robot_state_publisher, static)"
    assert lines[3:] == [
        f"      {child}  (broadcaster: /robot_state_publisher, static)"
        for child in ("base_scan", "imu_link", "wheel_left_link", "wheel_right_link")
    ]


def test_frames_dot_is_view_frames_style(robot, processes) -> None:
    result = run(processes, "tf", "frames", "-t", "0.5", "--dot")
    assert result.code == 0, result.err
    lines = result.out.splitlines()
    assert lines[0] == "digraph G {"
    assert lines[1].startswith('"odom" -> "base_footprint"[label=" Broadcaster: /odometry\\n'
                               "Average rate: ")  # fmt: skip
    assert ('"base_link" -> "base_scan"[label=" Broadcaster: /robot_state_publisher\\n'
            "Average rate: static\\n") in result.out  # fmt: skip
    assert lines[-2:] == ['}->"odom";', "}"]


def test_echo_composes_odom_to_base_scan_through_the_tree(robot, processes, monkeypatch) -> None:
    monkeypatch.delenv("ROS_DISTRO", raising=False)  # Humble's quaternion line
    result = run(processes, "tf", "echo", "odom", "base_scan", "--once")
    assert result.code == 0, result.err
    lines = result.out.splitlines()
    # base_scan in base_footprint, then turned by the odometry yaw and moved by its x, y
    bx, by, bz = (
        a + b for a, b in zip(STATIC["base_link"][1], STATIC["base_scan"][1], strict=True)
    )
    c, s = math.cos(ODOM_YAW), math.sin(ODOM_YAW)
    expected = (ODOM_XY[0] + c * bx - s * by, ODOM_XY[1] + s * bx + c * by, bz)
    assert lines[0].startswith("At time ")
    assert lines[1] == "- Translation: [" + ", ".join(f"{v + 0.0:.3f}" for v in expected) + "]"
    assert lines[1] == "- Translation: [1.000, 1.968, 0.182]"
    half = ODOM_YAW / 2
    assert (
        lines[2]
        == f"- Rotation: in Quaternion [0.000, 0.000, {math.sin(half):.3f}, {math.cos(half):.3f}]"
    )
    assert lines[4] == "- Rotation: in RPY (degree) [0.000, -0.000, 90.000]"  # tf2's -0.0 pitch


def test_echo_of_an_unknown_frame_lists_the_known_ones_closest_first(robot, processes) -> None:
    result = run(processes, "tf", "echo", "odom", "base_scn", "--wait-time", "0.5")
    line = assert_user_error(result, "frame 'base_scn' does not exist; known frames: base_scan, ")
    assert "wheel_right_link" in line
    assert "odom" in line


def test_no_tf_data_is_one_clear_line_and_exit_1(processes) -> None:
    result = run(processes, "tf", "frames", "-t", "0.3")
    assert_user_error(result, "no TF data received on /tf or /tf_static within 0.3 s")
    assert result.out == ""


def test_frames_to_pdf_without_graphviz_is_drawn_by_rosl(
    robot, processes, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("PATH", f"{tmp_path / 'empty'}:{Path(sys.executable).parent}")
    target = tmp_path / "frames.pdf"
    result = run(processes, "tf", "frames", "-t", "0.5", "-o", str(target))
    assert result.code == 0, result.err
    assert target.read_bytes().startswith(b"%PDF")


def test_frames_to_an_unknown_picture_type_is_one_line_before_listening(
    rosl: Callable[..., Result], tmp_path: Path
) -> None:
    target = tmp_path / "frames.xyz"
    assert_user_error(rosl("tf", "frames", "-o", str(target)), "unknown file type")
    assert not target.exists()


def test_frames_to_a_dot_file(robot, processes, tmp_path: Path) -> None:
    target = tmp_path / "frames.gv"
    result = run(processes, "tf", "frames", "-t", "0.5", "-o", str(target))
    assert result.code == 0, result.err
    assert target.read_text().startswith('digraph G {\n"odom" -> "base_footprint"')
