"""The tf2 programs' command lines, parsed in-process (the processes are in test_tools)."""

from __future__ import annotations

import math

import pytest

from rosl.tf2 import echo, monitor, static_publisher
from rosl.tf2.errors import Tf2ArgumentError
from rosl.tf2.transform import Transform
from tests.tf2.support import close


def parsed(*args: str) -> static_publisher.StaticRequest:
    request = static_publisher.parse(list(args))
    assert request is not None
    return request


def test_flags_give_translation_and_a_rotation_from_roll_pitch_yaw_or_a_quaternion() -> None:
    request = parsed("--x", "1", "--y", "-2", "--roll", str(math.pi), "--frame-id", "a",
                     "--child-frame-id", "b")  # fmt: skip
    assert (request.frame_id, request.child_frame_id, request.old_style) == ("a", "b", False)
    t = request.transform()
    assert t.translation == (1.0, -2.0, 0.0)
    assert close(t.rotation, (1.0, 0.0, 0.0, 0.0))  # half a turn about x
    quaternion = parsed("--qz", "1", "--qw", "0", "--frame-id", "a", "--child-frame-id", "b")
    assert quaternion.transform().rotation == (0.0, 0.0, 1.0, 0.0)
    identity = parsed("--frame-id", "a", "--child-frame-id", "b").transform()
    assert identity == Transform()


def test_old_style_is_x_y_z_then_yaw_pitch_roll_or_a_quaternion() -> None:
    eight = parsed("1", "2", "3", "0.1", "0.2", "0.3", "map", "odom")
    assert eight.old_style
    assert (eight.frame_id, eight.child_frame_id) == ("map", "odom")
    t = eight.transform()
    assert t.translation == (1.0, 2.0, 3.0)
    assert close(t.euler(), (0.3, 0.2, 0.1))  # roll, pitch, yaw: given in the reverse order
    nine = parsed("0", "0", "0", "0", "0", "0.6", "0.8", "map", "odom").transform()
    assert nine.rotation == (0.0, 0.0, 0.6, 0.8)  # as given, not normalised


def test_help_is_no_request() -> None:
    assert static_publisher.parse(["--help"]) is None
    assert echo.parse(["-h"]) is None


def test_tf2_echo_takes_humbles_positional_rate_and_the_newer_options() -> None:
    assert echo.parse(["odom", "base"]) == echo.EchoRequest("odom", "base")
    assert echo.parse(["odom", "base", "10"]).rate == 10.0
    request = echo.parse(["odom", "base", "-r", "2.5", "-t", "12.5", "-p", "5"])
    assert (request.rate, request.time_ns, request.precision) == (2.5, 12_500_000_000, 5)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["odom", "base", "-p", "-1"], "-p: the precision must not be negative"),
        (["odom", "base", "-t", "-3"], "-t: the time must not be negative"),
        (["odom", "base", "-p", "2.5"], "-p: '2.5' is not an integer"),
        (["odom", "base", "-r"], "-r needs a value"),
        (["a", "b", "1", "extra"], "unexpected arguments 'extra'"),
    ],
)
def test_tf2_echo_refuses_bad_options(args: list[str], message: str) -> None:
    with pytest.raises(Tf2ArgumentError, match=message):
        echo.parse(args)


def test_echo_text_follows_the_precision() -> None:
    text = echo.echo_text(Transform((1.0, 0.0, 0.0)), 1_000_000_005, precision=1).splitlines()
    assert text[:2] == ["At time 1.5", "- Translation: [1.0, 0.0, 0.0]"]
    assert text[-1] == "    0.0    0.0    0.0    1.0"


def test_tf2_monitor_takes_no_frames_or_two() -> None:
    assert monitor.parse([]) is None
    assert monitor.parse(["a", "b"]) == ("a", "b")
    with pytest.raises(Tf2ArgumentError):
        monitor.parse(["a", "b", "c"])


def test_tf2_monitor_report_text() -> None:
    from types import SimpleNamespace

    from tests.tf2.support import transform

    tally = monitor.Tally()
    message = SimpleNamespace(transforms=[transform("world", "turtle1", seconds=10.0),
                                          transform("turtle1", "camera", seconds=9.0)])  # fmt: skip
    tally.add(message, "/turtle_broadcaster", 10.5)
    tally.add(message, "/turtle_broadcaster", 11.0)
    out, heading, nodes = monitor.report(tally, None)
    assert out == (
        "\n\n\nRESULTS: for all Frames\n\nFrames:\n"
        "Frame: camera, published by /turtle_broadcaster, Average Delay: 1.75, Max Delay: 2\n"
        "Frame: turtle1, published by /turtle_broadcaster, Average Delay: 0.75, Max Delay: 1\n"
    )
    assert heading == "\nAll Broadcasters:\n"
    assert nodes == "Node: /turtle_broadcaster 4 Hz, Average Delay: 1.25 Max Delay: 1.5\n"
    tally.chain = ["world", "turtle1"]
    tally.look(2.0)
    out, _, _ = monitor.report(tally, ("world", "turtle1"))
    assert out.startswith(
        "\n\n\nRESULTS: for world to turtle1\nChain is: world -> turtle1\n"
        "Net delay     avg = 0.02: max = 2\n\nFrames:\nFrame: turtle1, "
    )
    assert "camera" not in out  # only the chain's frames


def test_the_quaternion_line_follows_ros_distro(monkeypatch: pytest.MonkeyPatch) -> None:
    quaternion_line = 2
    monkeypatch.delenv("ROS_DISTRO", raising=False)
    humble = echo.echo_text(Transform(), 0).splitlines()[quaternion_line]
    assert humble == "- Rotation: in Quaternion [0.000, 0.000, 0.000, 1.000]"
    monkeypatch.setenv("ROS_DISTRO", "jazzy")
    jazzy = echo.echo_text(Transform(), 0).splitlines()[quaternion_line]
    assert jazzy == "- Rotation: in Quaternion (xyzw) [0.000, 0.000, 0.000, 1.000]"
