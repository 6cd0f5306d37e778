"""tf2's BufferCore semantics (tf2_py's test_buffer_core, tf2's caches), against hand-computed values."""

from __future__ import annotations

import math

import pytest
from rclpy.duration import Duration
from rclpy.time import Time
from tf2_py import (
    BufferCore,
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TransformException,
)

from tests.tf2.support import close, quat, transform, xyz, yaw


def test_set_transform_returns_none_and_a_static_transform_holds_at_every_time() -> None:
    core = BufferCore()
    assert core.set_transform_static(transform("bar", "foo", (2.0, 0.0, 0.0)), "test") is None
    assert core.can_transform_core("bar", "foo", Time(seconds=0.5)) == (True, "")
    assert core.can_transform_core("bar", "foo", Time(seconds=1e6))[0]


def test_one_dynamic_transform_holds_only_at_its_own_stamp() -> None:
    core = BufferCore()
    core.set_transform(transform("bar", "foo", (2.0, 0.0, 0.0), seconds=1.0), "test")
    assert core.can_transform_core("bar", "foo", Time(seconds=1.0))[0]
    ok, why = core.can_transform_core("bar", "foo", Time(seconds=0.5))
    assert not ok
    assert why == (
        "Lookup would require extrapolation at time 0.500000, but only time 1.000000 is in the "
        "buffer, when looking up transform from frame [foo] to frame [bar]"
    )


def test_extrapolation_into_the_future_and_the_past_in_tf2s_words() -> None:
    core = BufferCore()
    for seconds in (1.0, 2.0):
        core.set_transform(transform("bar", "foo", (2.0, 0.0, 0.0), seconds=seconds), "test")
    ok, why = core.can_transform_core("foo", "bar", Time(seconds=2.5))
    assert not ok
    assert why.startswith(
        "Lookup would require extrapolation into the future.  Requested time 2.500000 but the "
        "latest data is at time 2.000000"
    )
    ok, why = core.can_transform_core("foo", "bar", Time(seconds=0.5))
    assert not ok
    assert (
        "extrapolation into the past.  Requested time 0.500000 but the earliest data is at "
        "time 1.000000" in why
    )
    with pytest.raises(ExtrapolationException) as caught:
        core.lookup_transform_core("foo", "bar", Time(seconds=0.5))
    assert isinstance(caught.value, TransformException)


def test_between_two_stamps_translation_is_linear_and_rotation_is_slerped() -> None:
    core = BufferCore()
    core.set_transform(transform("odom", "base", (0.0, 0.0, 0.0), yaw(0.0), 10.0), "test")
    core.set_transform(transform("odom", "base", (4.0, 2.0, 0.0), yaw(math.pi / 2), 11.0), "t")
    quarter = core.lookup_transform_core("odom", "base", Time(seconds=10.25))
    assert close(xyz(quarter), (1.0, 0.5, 0.0))
    assert close(quat(quarter), yaw(math.pi / 8))  # a quarter of the way round a quarter turn
    assert (quarter.header.stamp.sec, quarter.header.stamp.nanosec) == (10, 250_000_000)
    assert (quarter.header.frame_id, quarter.child_frame_id) == ("odom", "base")


def test_time_zero_is_the_latest_time_every_edge_on_the_way_has_data_for() -> None:
    core = BufferCore()
    for seconds in (1.0, 2.0, 3.0):  # map->odom drifts along x, up to 3 s
        core.set_transform(transform("map", "odom", (seconds, 0.0, 0.0), seconds=seconds), "t")
    for seconds in (1.0, 2.0):  # odom->base only up to 2 s
        core.set_transform(transform("odom", "base", (0.0, seconds, 0.0), seconds=seconds), "t")
    core.set_transform_static(transform("base", "laser", (0.0, 0.0, 0.5)), "t")
    assert core.get_latest_common_time("map", "base") == Time(seconds=2.0)
    latest = core.lookup_transform_core("map", "laser", Time())
    assert (latest.header.stamp.sec, latest.header.stamp.nanosec) == (2, 0)
    assert close(xyz(latest), (2.0, 2.0, 0.5))  # map->odom taken at 2 s, not its newest 3 s
    static_only = core.lookup_transform_core("base", "laser", Time())
    assert (static_only.header.stamp.sec, static_only.header.stamp.nanosec) == (0, 0)


def test_a_lookup_goes_up_to_the_common_parent_and_down_again() -> None:
    core = BufferCore()
    core.set_transform_static(transform("base", "left", (0.0, 1.0, 0.0), yaw(math.pi / 2)), "t")
    core.set_transform_static(transform("base", "right", (0.0, -1.0, 0.0)), "t")
    core.set_transform_static(transform("left", "cam", (1.0, 0.0, 0.0)), "t")
    found = core.lookup_transform_core("right", "cam", Time())
    # cam sits at (0, 1) + R(90°)(1, 0, 0) = (0, 2, 0) in base; right is at (0, -1) unturned
    assert close(xyz(found), (0.0, 3.0, 0.0))
    assert close(quat(found), yaw(math.pi / 2))
    back = core.lookup_transform_core("cam", "right", Time())
    assert close(xyz(back), (-3.0, 0.0, 0.0))  # seen from cam, turned back by -90°
    assert core._chain("right", Time(), "cam", Time(), "right") == ["cam", "left", "base", "right"]


def test_the_lookup_of_what_was_set_returns_it_unchanged() -> None:
    core = BufferCore()
    sent = transform("bar", "foo", (2.0, 0.0, 0.0))
    core.set_transform(sent, "unittest")
    assert core.lookup_transform_core("bar", "foo", Time()) == sent


def test_unknown_frames_invalid_ids_and_separate_trees_raise_tf2s_exceptions() -> None:
    core = BufferCore()
    core.set_transform(transform("bar", "foo", (2.0, 0.0, 0.0)), "test")
    core.set_transform(transform("other", "tree"), "test")
    with pytest.raises(LookupException, match='"baz" passed to lookupTransform argument '
                                              "source_frame does not exist"):  # fmt: skip
        core.lookup_transform_core("bar", "baz", Time())
    with pytest.raises(InvalidArgumentException, match="frame_ids cannot start with a '/'"):
        core.lookup_transform_core("/bar", "foo", Time())
    with pytest.raises(InvalidArgumentException, match="frame_ids cannot be empty"):
        core.lookup_transform_core("", "foo", Time())
    with pytest.raises(ConnectivityException) as caught:
        core.lookup_transform_core("foo", "tree", Time())
    assert str(caught.value) == (
        "Could not find a connection between 'foo' and 'tree' because they are not part of "
        "the same tree.Tf has two or more unconnected trees."
    )
    ok, why = core.can_transform_core("bar", "nope", Time())
    assert not ok
    assert why == 'Invalid frame ID "nope" passed to canTransform argument source_frame - ' \
        "frame does not exist"  # fmt: skip


def test_transforms_tf2_refuses_are_not_stored() -> None:
    core = BufferCore()
    core.set_transform(transform("a", "a"), "t")  # self transform
    core.set_transform(transform("a", ""), "t")  # no child
    core.set_transform(transform("a", "b", q=(0.0, 0.0, 0.0, 2.0)), "t")  # not unit length
    core.set_transform(transform("a", "c", (math.nan, 0.0, 0.0)), "t")
    assert not core.can_transform_core("a", "b", Time())[0]
    assert not core._frameExists("c")
    core.set_transform(transform("/a", "/b"), "t")  # a leading slash is dropped
    assert core.can_transform_core("a", "b", Time())[0]


def test_the_cache_keeps_ten_seconds_behind_the_newest_and_refuses_older_data() -> None:
    core = BufferCore()
    for seconds in (0.0, 5.0, 11.0, 12.0):
        core.set_transform(transform("odom", "base", (seconds, 0.0, 0.0), seconds=seconds), "t")
    ok, why = core.can_transform_core("odom", "base", Time(seconds=3.0))
    assert not ok
    assert "earliest data is at time 5.000000" in why  # 0 s fell out of the 10 s window
    core.set_transform(transform("odom", "base", (0.0, 9.0, 0.0), seconds=1.0), "t")  # too old
    assert close(xyz(core.lookup_transform_core("odom", "base", Time(seconds=8.0))),
                 (8.0, 0.0, 0.0))  # fmt: skip
    short = BufferCore(Duration(seconds=1.0))
    for seconds in (0.0, 1.0, 2.0, 3.0):
        short.set_transform(transform("odom", "base", seconds=seconds), "t")
    assert not short.can_transform_core("odom", "base", Time(seconds=0.5))[0]
    assert short.can_transform_core("odom", "base", Time(seconds=2.5))[0]


def test_lookup_full_holds_the_fixed_frame_still_between_two_times() -> None:
    core = BufferCore()
    for seconds in (1.0, 2.0):  # the robot drives 1 m along x each second
        core.set_transform(transform("odom", "base", (seconds, 0.0, 0.0), seconds=seconds), "t")
    # where the robot was at 1 s, seen from where it is at 2 s: 1 m behind
    full = core.lookup_transform_full_core("base", Time(seconds=2.0), "base",
                                           Time(seconds=1.0), "odom")  # fmt: skip
    assert close(xyz(full), (-1.0, 0.0, 0.0))
    assert core.can_transform_full_core("base", Time(seconds=2.0), "base", Time(seconds=1.0),
                                        "odom") == (True, "")  # fmt: skip
    assert not core.can_transform_full_core("base", Time(seconds=3.0), "base",
                                            Time(seconds=1.0), "odom")[0]  # fmt: skip


def test_clear_forgets_dynamic_data_and_the_texts_name_every_frame() -> None:
    core = BufferCore()
    core.set_transform(transform("bar", "foo", seconds=1.0), "unittest")
    core.set_transform_static(transform("bar", "fixed"), "unittest")
    assert core.all_frames_as_string() == (
        "Frame foo exists with parent bar.\nFrame fixed exists with parent bar.\n"
    )
    yaml_text = core.all_frames_as_yaml()
    assert "foo: \n  parent: 'bar'\n  broadcaster: 'unittest'\n" in yaml_text
    core.clear()
    assert not core.can_transform_core("foo", "bar", Time())[0]
    assert core.can_transform_core("fixed", "bar", Time())[0]  # static transforms stay
