"""TF math, the frame buffer and the tf2_echo / view_frames texts, without the bus."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from rosl.introspection.errors import IntrospectionError
from rosl.introspection.tf import TfBuffer, echo_text, frames_dot, frames_text
from rosl.tf2.transform import Transform


def yaw(angle: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


def transform_stamped(parent: str, child: str, xyz, q=(0.0, 0.0, 0.0, 1.0), stamp_ns: int = 0):
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    return SimpleNamespace(
        header=SimpleNamespace(frame_id=parent, stamp=SimpleNamespace(sec=sec, nanosec=nanosec)),
        child_frame_id=child,
        transform=SimpleNamespace(
            translation=SimpleNamespace(x=xyz[0], y=xyz[1], z=xyz[2]),
            rotation=SimpleNamespace(x=q[0], y=q[1], z=q[2], w=q[3]),
        ),
    )


def turtlebot() -> TfBuffer:
    buffer = TfBuffer()
    static = [
        transform_stamped("base_footprint", "base_link", (0.0, 0.0, 0.010)),
        transform_stamped("base_link", "base_scan", (-0.032, 0.0, 0.172)),
        transform_stamped("base_link", "imu_link", (-0.032, 0.0, 0.068)),
        transform_stamped("base_link", "wheel_left_link", (0.0, 0.08, 0.023)),
        transform_stamped("base_link", "wheel_right_link", (0.0, -0.08, 0.023)),
    ]
    buffer.add(SimpleNamespace(transforms=static), True, (1, 1), 0)
    for i in range(11):  # 10 Hz for one second
        odom = transform_stamped("odom", "base_footprint", (1.0, 2.0, 0.0), yaw(math.pi / 2),
                                 stamp_ns=5_000_000_000 + i * 100_000_000)  # fmt: skip
        buffer.add(SimpleNamespace(transforms=[odom]), False, (2, 1), i * 100_000_000)
    for edge in buffer.edges.values():
        edge.broadcasters = ("/robot_state_publisher",) if edge.static else ("/odom_node",)
    return buffer


def close(a, b) -> bool:
    return all(math.isclose(x, y, abs_tol=1e-9) for x, y in zip(a, b, strict=True))


def test_a_transform_times_its_inverse_is_the_identity() -> None:
    t = Transform((1.0, -2.0, 0.5), (0.1, 0.2, 0.3, math.sqrt(1 - 0.14)))
    both = t * t.inverse()
    assert close(both.translation, (0.0, 0.0, 0.0))
    assert close(both.rotation, (0.0, 0.0, 0.0, 1.0))


def test_rotation_applies_before_translation_when_composing() -> None:
    quarter = Transform((1.0, 0.0, 0.0), yaw(math.pi / 2))
    moved = quarter * Transform((1.0, 0.0, 0.0))
    assert close(moved.translation, (1.0, 1.0, 0.0))
    assert close(Transform(rotation=yaw(0.3)).rpy(), (0.0, 0.0, 0.3))


def test_lookup_composes_down_the_tree_through_the_common_ancestor() -> None:
    buffer = turtlebot()
    pose, stamp = buffer.lookup("odom", "base_scan")
    # base_scan sits at (-0.032, 0, 0.182) in base_footprint, which is turned 90 degrees
    assert close(pose.translation, (1.0, 2.0 - 0.032, 0.182))
    assert close(pose.rotation, yaw(math.pi / 2))
    assert stamp == 6_000_000_000  # the dynamic edge's latest stamp
    sideways, static_stamp = buffer.lookup("wheel_left_link", "wheel_right_link")
    assert close(sideways.translation, (0.0, -0.16, 0.0))
    assert static_stamp == 0


def test_unknown_frames_list_the_known_ones_closest_first() -> None:
    with pytest.raises(IntrospectionError) as caught:
        turtlebot().lookup("odom", "base_scn")
    message = str(caught.value)
    assert message.startswith("frame 'base_scn' does not exist; known frames: base_scan, ")
    assert "odom" in message
    assert "\n" not in message


def test_frames_in_separate_trees_are_not_connected() -> None:
    buffer = turtlebot()
    buffer.add(SimpleNamespace(transforms=[transform_stamped("map", "marker", (0, 0, 0))]),
               False, (3, 1), 0)  # fmt: skip
    with pytest.raises(IntrospectionError, match="'odom' is in the tree of 'odom'"):
        buffer.lookup("odom", "marker")
    assert frames_text(buffer).splitlines()[-1] == "note: 2 separate trees (roots: map, odom)"


def test_echo_text_has_tf2_echo_lines_with_three_decimals(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("ROS_DISTRO", raising=False)  # Humble's quaternion line
    pose, stamp = turtlebot().lookup("odom", "base_scan")
    lines = echo_text(pose, stamp).splitlines()
    # as tf2_echo prints them: nanoseconds unpadded, tf2's getEulerYPR pitch of -0.0
    assert lines[:5] == [
        "At time 6.0",
        "- Translation: [1.000, 1.968, 0.182]",
        "- Rotation: in Quaternion [0.000, 0.000, 0.707, 0.707]",
        "- Rotation: in RPY (radian) [0.000, -0.000, 1.571]",
        "- Rotation: in RPY (degree) [0.000, -0.000, 90.000]",
    ]
    assert lines[5] == "- Matrix:"
    assert lines[6].split() == ["0.000", "-1.000", "0.000", "1.000"]


def test_frames_text_puts_the_root_first_and_children_indented() -> None:
    assert frames_text(turtlebot()).splitlines() == [
        "odom",
        "  base_footprint  (broadcaster: /odom_node, average rate: 10.0 Hz)",
        "    base_link  (broadcaster: /robot_state_publisher, static)",
        "      base_scan  (broadcaster: /robot_state_publisher, static)",
        "      imu_link  (broadcaster: /robot_state_publisher, static)",
        "      wheel_left_link  (broadcaster: /robot_state_publisher, static)",
        "      wheel_right_link  (broadcaster: /robot_state_publisher, static)",
    ]


def test_frames_dot_is_view_frames_digraph() -> None:
    dot = frames_dot(turtlebot(), recorded_ns=7_500_000_000).splitlines()
    assert dot[0] == "digraph G {"
    assert dot[1] == (
        '"odom" -> "base_footprint"[label=" Broadcaster: /odom_node\\nAverage rate: 10.0\\n'
        'Buffer length: 1.0\\nMost recent transform: 6.0\\nOldest transform: 5.0\\n"];'
    )
    assert dot[2].startswith('"base_footprint" -> "base_link"[label=" Broadcaster: '
                             '/robot_state_publisher\\nAverage rate: static\\n')  # fmt: skip
    assert '"Recorded at time: 7.5"[ shape=plaintext ] ;' in dot
    assert dot[-2:] == ['}->"odom";', "}"]
