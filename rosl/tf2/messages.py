"""Between messages and tf2's values: stamps to nanoseconds, TransformStamped to Transform.

Times are accepted as tf2_py accepts them: anything with ``sec`` and ``nanosec`` (a
``builtin_interfaces/msg/Time``) or with ``nanoseconds`` (``rclpy.time.Time``, ``Duration``).
"""

from __future__ import annotations

from typing import Any

from rosl.idl.registry import get_message_class
from rosl.tf2.transform import Transform

NS = 1_000_000_000


def to_ns(value: Any, what: str = "time") -> int:
    """Nanoseconds of a Time/Duration message or an rclpy Time/Duration.

    Raises:
        TypeError: ``value`` has neither ``sec``/``nanosec`` nor ``nanoseconds`` (as tf2_py).
    """
    if hasattr(value, "sec") and hasattr(value, "nanosec"):
        return int(value.sec) * NS + int(value.nanosec)
    if hasattr(value, "nanoseconds"):
        return int(value.nanoseconds)
    raise TypeError(f"{what} must have sec and nanosec, or nanoseconds.")


def message_class(name: str) -> Any:
    """The class of ``geometry_msgs/msg/<name>``-style type names."""
    return get_message_class(name)


def time_msg(stamp_ns: int) -> Any:
    """A builtin_interfaces/msg/Time."""
    sec, nanosec = divmod(stamp_ns, NS)
    return message_class("builtin_interfaces/msg/Time")(sec=sec, nanosec=nanosec)


def transform_of(msg: Any) -> Transform:
    """The Transform of a geometry_msgs/msg/Transform (or TransformStamped)."""
    t = getattr(msg, "transform", msg)
    p, q = t.translation, t.rotation
    return Transform((float(p.x), float(p.y), float(p.z)),
                     (float(q.x), float(q.y), float(q.z), float(q.w)))  # fmt: skip


def stamped(transform: Transform, target: str, source: str, stamp_ns: int) -> Any:
    """A geometry_msgs/msg/TransformStamped target←source."""
    msg = message_class("geometry_msgs/msg/TransformStamped")()
    msg.header.stamp = time_msg(stamp_ns)
    msg.header.frame_id = target
    msg.child_frame_id = source
    fill_transform(msg.transform, transform)
    return msg


def fill_transform(msg: Any, transform: Transform) -> None:
    """Write ``transform`` into a geometry_msgs/msg/Transform."""
    p, q = msg.translation, msg.rotation
    p.x, p.y, p.z = transform.translation
    q.x, q.y, q.z, q.w = transform.rotation


__all__ = ["fill_transform", "message_class", "stamped", "time_msg", "to_ns", "transform_of"]
