"""Building TransformStamped messages for the tf2 tests."""

from __future__ import annotations

import math
from typing import Any

from rosl.idl.registry import get_message_class


def yaw(angle: float) -> tuple[float, float, float, float]:
    """A quaternion turning ``angle`` radians about z."""
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


def transform(
    parent: str, child: str, xyz: tuple[float, float, float] = (0.0, 0.0, 0.0),
    q: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0), seconds: float = 0.0,
) -> Any:  # fmt: skip
    """parent←child at ``seconds``."""
    t = get_message_class("geometry_msgs/msg/TransformStamped")()  # this test's class
    t.header.frame_id, t.child_frame_id = parent, child
    t.header.stamp.sec, t.header.stamp.nanosec = divmod(round(seconds * 1e9), 1_000_000_000)
    v, r = t.transform.translation, t.transform.rotation
    v.x, v.y, v.z = xyz
    r.x, r.y, r.z, r.w = q
    return t


def xyz(msg: Any) -> tuple[float, float, float]:
    """The translation of a TransformStamped."""
    v = msg.transform.translation
    return (v.x, v.y, v.z)


def quat(msg: Any) -> tuple[float, float, float, float]:
    """The rotation of a TransformStamped."""
    r = msg.transform.rotation
    return (r.x, r.y, r.z, r.w)


def close(a: Any, b: Any, tol: float = 1e-9) -> bool:
    """Element-wise closeness of two sequences of floats."""
    return len(a) == len(b) and all(
        math.isclose(x, y, abs_tol=tol) for x, y in zip(a, b, strict=True)
    )
