"""``rosl run tf2_ros static_transform_publisher | tf2_echo | tf2_monitor`` as real processes."""

from __future__ import annotations

import math
import subprocess
from typing import TYPE_CHECKING

import pytest

from tests.graph.support import Watched

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

TURTLE = """
import rosl
from geometry_msgs.msg import TransformStamped
from tf2_ros import TransformBroadcaster

rosl.init([])
node = rosl.Node('turtle_broadcaster')
broadcaster = TransformBroadcaster(node)


def tick():
    t = TransformStamped()
    t.header.stamp = node.get_clock().now().to_msg()
    t.header.frame_id, t.child_frame_id = 'world', 'turtle1'
    t.transform.translation.x = 1.0
    broadcaster.sendTransform(t)


node.create_timer(0.05, tick)
print('ready', flush=True)
rosl.spin(node)
"""


def tf2_ros(processes: Processes, *args: str) -> Watched:
    return Watched(processes.rosl("run", "tf2_ros", *args))


def echo_block(processes: Processes, source: str, target: str) -> list[str]:
    """The first block tf2_echo prints (10 lines), once it has the transform."""
    echo = tf2_ros(processes, "tf2_echo", source, target)
    assert echo.wait_for(r"^  0\.000  0\.000  0\.000  1\.000$", timeout=60), echo.text("err")
    lines = echo.lines()
    start = next(i for i, line in enumerate(lines) if line.startswith("At time "))
    echo.interrupt()
    return lines[start : start + 10]


def test_the_quaternion_form_is_echoed_in_tf2_echos_own_text(processes: Processes) -> None:
    publisher = tf2_ros(processes, "static_transform_publisher",
                        "1", "2", "3", "0", "0", "1", "0", "parent", "child")  # fmt: skip
    assert echo_block(processes, "parent", "child") == [
        "At time 0.0",  # static: stamped 0, printed as tf2_echo does (sec.nanosec)
        "- Translation: [1.000, 2.000, 3.000]",
        "- Rotation: in Quaternion [0.000, 0.000, 1.000, 0.000]",
        "- Rotation: in RPY (radian) [0.000, -0.000, 3.142]",
        "- Rotation: in RPY (degree) [0.000, -0.000, 180.000]",
        "- Matrix:",
        " -1.000  0.000  0.000  1.000",
        "  0.000 -1.000  0.000  2.000",
        "  0.000  0.000  1.000  3.000",
        "  0.000  0.000  0.000  1.000",
    ]
    # the other way round: half a turn back, so the offset is undone in the turned frame
    assert echo_block(processes, "child", "parent")[1] == "- Translation: [1.000, 2.000, -3.000]"
    assert publisher.wait_for("Spinning until stopped - publishing transform", "err")
    assert publisher.matching(r"\[static_transform_publisher_[0-9A-Za-z]{16}\]", "err")


def test_the_flag_style_with_roll_pitch_yaw(processes: Processes) -> None:
    tf2_ros(processes, "static_transform_publisher", "--x", "0.5", "--yaw", str(math.pi / 2),
            "--frame-id", "base_link", "--child-frame-id", "laser")  # fmt: skip
    block = echo_block(processes, "base_link", "laser")
    assert block[1:5] == [
        "- Translation: [0.500, 0.000, 0.000]",
        "- Rotation: in Quaternion [0.000, 0.000, 0.707, 0.707]",
        "- Rotation: in RPY (radian) [0.000, -0.000, 1.571]",
        "- Rotation: in RPY (degree) [0.000, -0.000, 90.000]",
    ]


def test_the_old_positional_style_is_yaw_pitch_roll_and_warns(processes: Processes) -> None:
    publisher = tf2_ros(processes, "static_transform_publisher",
                        "0", "0", "1", str(math.pi), "0", "0", "map", "marker")  # fmt: skip
    block = echo_block(processes, "map", "marker")
    assert block[2] == "- Rotation: in Quaternion [0.000, 0.000, 1.000, 0.000]"
    assert block[4] == "- Rotation: in RPY (degree) [0.000, -0.000, 180.000]"
    assert publisher.wait_for("old-style arguments are deprecated", "err")


def test_tf2_monitor_reports_frames_and_broadcasters(processes: Processes) -> None:
    Watched(processes.python(TURTLE)).wait_ready()
    tf2_ros(processes, "static_transform_publisher", "--z", "0.2",
            "--frame-id", "turtle1", "--child-frame-id", "camera")  # fmt: skip
    everything = tf2_ros(processes, "tf2_monitor")
    chain = tf2_ros(processes, "tf2_monitor", "world", "camera")
    assert everything.wait_for(r"^Node: /turtle_broadcaster", timeout=90), everything.text("err")
    # the static publisher may be heard a report later than the turtle: wait for its line
    assert everything.wait_for(
        r"^Frame: camera, published by /static_transform_publisher_\w+", timeout=90
    ), everything.text()
    out = everything.text()
    assert "RESULTS: for all Frames\n\nFrames:\n" in out
    assert everything.matching(r"^Frame: turtle1, published by /turtle_broadcaster, "
                               r"Average Delay: [-0-9.e+]+, Max Delay: [0-9.e+]+$")  # fmt: skip
    rate = everything.matching(r"^Node: /turtle_broadcaster ([0-9.e+]+) Hz, Average Delay: ")
    assert 1.0 < float(rate[0][1]) < 1000.0  # 20 Hz, over the time the monitor watched
    assert everything.wait_for("^All Broadcasters:$", "err")  # tf2_monitor writes it to stderr
    assert chain.wait_for(r"^Chain is: ", timeout=90), chain.text("err")
    assert chain.lines()[0].startswith(
        "Waiting for transform chain to become available between world and camera "
    )
    assert chain.matching("^RESULTS: for world to camera$")
    assert chain.matching("^Chain is: (.*)$")[0][1] == "world -> turtle1 -> camera"
    assert chain.matching(r"^Net delay     avg = [-0-9.e+]+: max = [-0-9.e+]+$")


@pytest.mark.parametrize(
    ("program", "args", "message"),
    [
        ("static_transform_publisher", ["--x", "abc", "--frame-id", "a", "--child-frame-id", "b"],
         "--x: 'abc' is not a number"),
        ("static_transform_publisher", ["--x", "1"], "no parent frame: give --frame-id"),
        ("static_transform_publisher", ["--frame-id", "a"], "no child frame: give --child-frame-id"),
        ("static_transform_publisher", ["1", "2", "3", "left", "0", "0", "a", "b"],
         "yaw: 'left' is not a number"),
        ("static_transform_publisher", ["--qx", "1", "--roll", "1", "--frame-id", "a",
                                        "--child-frame-id", "b"], "not both"),
        ("static_transform_publisher", ["--frame-id", "a", "--child-frame-id", "a"],
         "from 'a' to itself"),
        ("static_transform_publisher", ["1", "2", "a"], "unexpected arguments '1 2 a'"),
        ("static_transform_publisher", ["--frame-id"], "--frame-id needs a value"),
        ("static_transform_publisher", ["1", "2", "3", "0", "0", "0", "a", "b", "--x", "1"],
         "cannot be mixed"),
        ("tf2_echo", ["odom"], "give SOURCE_FRAME and TARGET_FRAME"),
        ("tf2_echo", ["odom", "base", "fast"], "rate: 'fast' is not a number"),
        ("tf2_echo", ["odom", "base", "0"], "the rate must be a positive number"),
        ("tf2_echo", ["odom", "base", "-x"], "unknown option -x"),
        ("tf2_monitor", ["odom"], "usage: tf2_monitor [FRAME_A FRAME_B]"),
    ],
)  # fmt: skip
def test_bad_arguments_are_one_line_and_exit_1(
    processes: Processes, program: str, args: list[str], message: str
) -> None:
    child = processes.rosl("run", "tf2_ros", program, *args)
    try:
        out, err = child.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail(f"{program} {args} did not stop")
    assert child.returncode == 1, (out, err)
    assert "Traceback" not in err
    assert err.splitlines() == [f"{program}: {err.splitlines()[0].split(': ', 1)[1]}"]
    assert message in err


def test_help_is_the_usage_and_exit_0(processes: Processes) -> None:
    for program in ("static_transform_publisher", "tf2_echo"):
        child = processes.rosl("run", "tf2_ros", program, "--help")
        out, _ = child.communicate(timeout=60)
        assert child.returncode == 0
        assert out.startswith(f"usage: {program} ")


def test_tf2_echos_buffer_answers_the_tf2_frames_service(processes: Processes) -> None:
    tf2_ros(processes, "static_transform_publisher", "--frame-id", "a", "--child-frame-id", "b")
    echo = tf2_ros(processes, "tf2_echo", "a", "b")
    assert echo.wait_for("^At time ", timeout=60), echo.text("err")
    call = processes.rosl("service", "call", "/tf2_frames", "tf2_msgs/srv/FrameGraph")
    out, err = call.communicate(timeout=60)
    assert call.returncode == 0, err
    assert "frame_yaml=\"b: \\n  parent: 'a'\\n  broadcaster: 'default_authority'\\n" in out


LAUNCH = """
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription([
        Node(package='tf2_ros', executable='static_transform_publisher', name='base_to_laser',
             arguments=['--x', '0.1', '--z', '0.2', '--frame-id', 'base_link',
                        '--child-frame-id', 'laser']),
        Node(package='tf2_ros', executable='static_transform_publisher',
             arguments=['0', '0', '1', '0', '0', '0', 'laser', 'lens']),
    ])
"""


def test_a_launch_file_starts_static_transform_publishers_as_ros2_launch_would(
    processes: Processes, tmp_path: Path
) -> None:
    path = tmp_path / "tf.launch.py"
    path.write_text(LAUNCH)
    launch = Watched(processes.rosl("launch", str(path)))
    block = echo_block(processes, "base_link", "lens")
    assert block[1] == "- Translation: [0.100, 0.000, 1.200]"
    assert launch.wait_for(r"\[base_to_laser\]: Spinning until stopped", timeout=30)
    assert launch.interrupt() == 0
