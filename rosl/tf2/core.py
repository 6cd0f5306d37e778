"""tf2_py's ``BufferCore``: the frame tree behind the method names ROS 2 Python code calls.

Transforms go in as ``geometry_msgs/msg/TransformStamped`` (``set_transform``,
``set_transform_static``) and come out as TransformStamped (``lookup_transform_core``,
``lookup_transform_full_core``); ``can_transform_core`` answers ``(bool, message)``. The tree
itself (:class:`~rosl.tf2.tree.FrameTree`) is the one ``rosl tf`` reads as well.
A transform tf2 would refuse (same frames, no frame id, NaN, a quaternion that is not unit
length, data older than the cache) is logged with tf2's words and ignored.
"""

from __future__ import annotations

import math
from typing import Any

from rosl.node.logging import get_logger
from rosl.tf2.cache import DEFAULT_CACHE_TIME_NS, seconds_text
from rosl.tf2.messages import stamped, to_ns, transform_of
from rosl.tf2.tree import FrameTree

QUATERNION_TOLERANCE = 10e-3


class BufferCore(FrameTree):
    """Stores transforms and answers lookups between frames (tf2_py.BufferCore)."""

    def __init__(self, cache_time: Any = None) -> None:
        super().__init__(
            DEFAULT_CACHE_TIME_NS if cache_time is None else to_ns(cache_time, "duration")
        )
        self._log = get_logger("tf2")

    # --- writing -----------------------------------------------------------------------------

    def set_transform(self, transform: Any, authority: str) -> None:
        """Store a dynamic transform (logged and ignored when tf2 would refuse it)."""
        self._set(transform, authority, static=False)

    def set_transform_static(self, transform: Any, authority: str) -> None:
        """Store a static transform, valid at every time."""
        self._set(transform, authority, static=True)

    def _set(self, msg: Any, authority: str, static: bool) -> bool:
        parent = msg.header.frame_id.removeprefix("/")
        child = msg.child_frame_id.removeprefix("/")
        transform = transform_of(msg)
        stamp = to_ns(msg.header.stamp)
        if problem := _refusal(parent, child, authority, transform.translation,
                               transform.rotation):  # fmt: skip
            self._log.error(problem)
            return False
        if not self.insert(parent, child, stamp, transform, authority, static):
            self._log.warning(
                f"TF_OLD_DATA ignoring data from the past for frame {child} at time "
                f"{seconds_text(stamp)} according to authority {authority}\nPossible reasons "
                "are listed at http://wiki.ros.org/tf/Errors%20explained"
            )
            return False
        return True

    # --- reading (tf2_py names) --------------------------------------------------------------

    def can_transform_core(
        self, target_frame: str, source_frame: str, time: Any
    ) -> tuple[bool, str]:
        """(whether target←source is known at ``time``, tf2's reason when not)."""
        return self.possible(target_frame, source_frame, to_ns(time))

    def can_transform_full_core(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any,
        fixed_frame: str,
    ) -> tuple[bool, str]:  # fmt: skip
        """Whether target(target_time)←fixed←source(source_time) is known."""
        for frame, where in ((target_frame, "target_frame"), (source_frame, "source_frame"),
                             (fixed_frame, "fixed_frame")):  # fmt: skip
            if message := self.check(frame, f"canTransform argument {where}"):
                return False, message
        ok, message = self.possible(target_frame, fixed_frame, to_ns(target_time))
        if not ok:
            return ok, message
        return self.possible(fixed_frame, source_frame, to_ns(source_time))

    def lookup_transform_core(self, target_frame: str, source_frame: str, time: Any) -> Any:
        """The TransformStamped target←source at ``time`` (0: the latest common time).

        Raises:
            TransformException: LookupException, ConnectivityException, ExtrapolationException
                or InvalidArgumentException, with tf2's message.
        """
        transform, stamp = self.lookup(target_frame, source_frame, to_ns(time))
        return stamped(transform, target_frame, source_frame, stamp)

    def lookup_transform_full_core(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any,
        fixed_frame: str,
    ) -> Any:  # fmt: skip
        """target(target_time)←source(source_time), through ``fixed_frame`` held still."""
        transform, stamp = self.lookup_full(
            target_frame, to_ns(target_time), source_frame, to_ns(source_time), fixed_frame
        )
        return stamped(transform, target_frame, source_frame, stamp)

    def lookup_full(
        self, target: str, target_ns: int, source: str, source_ns: int, fixed: str
    ) -> tuple[Any, int]:
        """target(target_ns)←fixed←source(source_ns), and the time of the second half."""
        for frame, where in ((target, "target_frame"), (source, "source_frame"),
                             (fixed, "fixed_frame")):  # fmt: skip
            self.validate(frame, f"lookupTransform argument {where}")
        fixed_from_source, _ = self.lookup(fixed, source, source_ns)
        target_from_fixed, stamp = self.lookup(target, fixed, target_ns)
        return target_from_fixed * fixed_from_source, stamp

    def get_latest_common_time(self, target_frame: str, source_frame: str) -> Any:
        """The latest time both frames' chains have data for, as an rclpy Time."""
        from rosl.node.clock import Time

        for frame in (target_frame, source_frame):
            self.validate(frame, "get_latest_common_time")
        return Time(nanoseconds=self.latest_common_time(target_frame, source_frame))

    def all_frames_as_string(self) -> str:
        """'Frame X exists with parent Y.' lines."""
        return self.frames_text()

    def all_frames_as_yaml(self) -> str:
        """Each frame's parent, broadcaster, rate and stamps as YAML."""
        return self.frames_yaml()

    def _frameExists(self, frame_id: str) -> bool:  # noqa: N802 - tf2_py's name
        return frame_id in self.known

    def _getFrameStrings(self) -> list[str]:  # noqa: N802 - tf2_py's name
        return list(self.known)

    def _chain(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any,
        fixed_frame: str,
    ) -> list[str]:  # fmt: skip
        del target_time, source_time
        return self.chain(target_frame, source_frame) if fixed_frame else []


def _refusal(
    parent: str, child: str, authority: str, xyz: tuple[float, ...], q: tuple[float, ...]
) -> str:
    """tf2's error for a transform it ignores, or ''."""
    if child == parent:
        return (
            f'TF_SELF_TRANSFORM: Ignoring transform from authority "{authority}" with frame_id '
            f'and  child_frame_id "{child}" because they are the same'
        )
    if not child:
        return (
            f'TF_NO_CHILD_FRAME_ID: Ignoring transform from authority "{authority}" because '
            "child_frame_id not set "
        )
    if not parent:
        return (
            f'TF_NO_FRAME_ID: Ignoring transform with child_frame_id "{child}"  from authority '
            f'"{authority}" because frame_id not set'
        )
    if any(math.isnan(v) for v in (*xyz, *q)):
        return (
            f'TF_NAN_INPUT: Ignoring transform for child_frame_id "{child}" from authority '
            f'"{authority}" because of a nan value in the transform ({_f(xyz)}) ({_f(q)})'
        )
    if abs(sum(v * v for v in q) - 1.0) >= QUATERNION_TOLERANCE:
        return (
            f'TF_DENORMALIZED_QUATERNION: Ignoring transform for child_frame_id "{child}" from '
            f'authority "{authority}" because of an invalid quaternion in the transform ({_f(q)})'
        )
    return ""


def _f(values: tuple[float, ...]) -> str:
    return " ".join(f"{v:f}" for v in values)


__all__ = ["BufferCore"]
