"""``rosl viz``'s fixed frame: ``odom``, else the frame the odometry is given in (no bus)."""

from __future__ import annotations

from typing import Any

import pytest

from rosl.idl import registry
from rosl.introspection.errors import IntrospectionError
from rosl.introspection.viz import ODOMETRY, TF, VizBuilder


def message(type_name: str, **fields: Any) -> Any:
    return registry.get_message_class(type_name)(**fields)


def odometry(frame: str, x: float) -> Any:
    odom = message(ODOMETRY)
    odom.header.frame_id = frame
    odom.child_frame_id = "base"
    odom.pose.pose.position.x = x
    odom.pose.pose.orientation.w = 1.0
    return odom


def tf_edges(*edges: tuple[str, str]) -> Any:
    transforms = []
    for parent, child in edges:
        stamped = message("geometry_msgs/msg/TransformStamped")
        stamped.header.frame_id = parent
        stamped.child_frame_id = child
        stamped.transform.rotation.w = 1.0
        transforms.append(stamped)
    return message(TF, transforms=transforms)


def builder_with(*odometry_frames: tuple[str, str], fixed: str | None = None) -> VizBuilder:
    builder = VizBuilder(fixed)
    builder.add("/tf_static", TF, tf_edges(*(("world", f) for _, f in odometry_frames)), 0)
    for topic, frame in odometry_frames:
        builder.add(topic, ODOMETRY, odometry(frame, 1.0), 1)
    return builder


def test_without_odom_the_odometrys_frame_is_the_fixed_frame_and_the_note_says_so() -> None:
    builder = builder_with(("/dolly/odom", "odom_demo"))

    scene = builder.scene("t")

    assert scene.frame == "odom_demo"
    assert builder.note == (
        "fixed frame: odom_demo (there is no 'odom' frame; odom_demo is the frame of /dolly/odom)"
    )
    assert ("/dolly/odom pose", (1.0, 0.0), 0.0) in scene.frames


def test_with_several_odometry_frames_the_first_topics_is_chosen_and_the_rest_named() -> None:
    builder = builder_with(("/robot_b/odom", "b_odom"), ("/robot_a/odom", "a_odom"))

    assert builder.scene("t").frame == "a_odom"
    assert builder.note is not None
    assert builder.note.startswith("fixed frame: a_odom (there is no 'odom' frame; ")
    assert "other odometry frames: b_odom (/robot_b/odom); pick one with --fixed-frame" in (
        builder.note
    )


def test_odom_stays_the_fixed_frame_when_the_tree_has_it() -> None:
    builder = builder_with(("/odom", "odom"), ("/dolly/odom", "odom_demo"))

    assert builder.scene("t").frame == "odom"
    assert builder.note is None


def test_a_fixed_frame_asked_for_is_kept_even_when_missing() -> None:
    builder = builder_with(("/dolly/odom", "odom_demo"), fixed="odom")

    with pytest.raises(IntrospectionError, match="fixed frame 'odom' is not in the TF tree"):
        builder.scene("t")
    assert builder.note is None
