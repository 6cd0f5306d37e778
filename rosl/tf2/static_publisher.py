"""``static_transform_publisher``: publish one static transform on /tf_static until stopped.

Both argument styles of tf2_ros's program: flags (``--x --y --z``, ``--qx --qy --qz --qw``
or ``--roll --pitch --yaw``, ``--frame-id``, ``--child-frame-id``) and the deprecated
positional ``x y z yaw pitch roll frame_id child_frame_id`` / ``x y z qx qy qz qw frame_id
child_frame_id``. A mistake is one line and exit 1. The node is
``static_transform_publisher_<16 random characters>`` with the transform as read-only
parameters.
"""

from __future__ import annotations

import random
import string
from dataclasses import dataclass, field
from typing import Any

from rosl.tf2.errors import Tf2ArgumentError
from rosl.tf2.program import run, user_args
from rosl.tf2.transform import Transform, quaternion_from_rpy

USAGE = """\
usage: static_transform_publisher [--x X] [--y Y] [--z Z] [--qx QX] [--qy QY] [--qz QZ]
                                  [--qw QW] [--roll ROLL] [--pitch PITCH] [--yaw YAW]
                                  --frame-id FRAME_ID --child-frame-id CHILD_FRAME_ID
       static_transform_publisher X Y Z YAW PITCH ROLL FRAME_ID CHILD_FRAME_ID   (deprecated)
       static_transform_publisher X Y Z QX QY QZ QW FRAME_ID CHILD_FRAME_ID      (deprecated)

Publishes the transform FRAME_ID <- CHILD_FRAME_ID on /tf_static until stopped.
Offsets are in meters, angles in radians; with no rotation or translation given, the
identity is published. The rotation is a quaternion or roll/pitch/yaw, not both."""

_NUMBERS = ("--x", "--y", "--z", "--qx", "--qy", "--qz", "--qw", "--roll", "--pitch", "--yaw")
_FRAMES = ("--frame-id", "--child-frame-id")


@dataclass(slots=True)
class StaticRequest:
    """What the command line asked for."""

    values: dict[str, float] = field(default_factory=dict)  # by flag, as given
    frame_id: str = ""
    child_frame_id: str = ""
    old_style: bool = False

    def transform(self) -> Transform:
        """The transform asked for (the quaternion as given, else from roll/pitch/yaw)."""
        v = self.values
        xyz = (v.get("--x", 0.0), v.get("--y", 0.0), v.get("--z", 0.0))
        if any(k in v for k in ("--qx", "--qy", "--qz", "--qw")):
            q = (v.get("--qx", 0.0), v.get("--qy", 0.0), v.get("--qz", 0.0), v.get("--qw", 1.0))
        else:
            q = quaternion_from_rpy(
                v.get("--roll", 0.0), v.get("--pitch", 0.0), v.get("--yaw", 0.0)
            )
        return Transform(xyz, q)


def _number(flag: str, text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise Tf2ArgumentError(f"{flag}: '{text}' is not a number") from None


def parse(args: list[str]) -> StaticRequest | None:
    """The request in ``args`` (without the program name); None when help was asked for.

    Raises:
        Tf2ArgumentError: a bad number, a missing value or frame id, mixed styles.
    """
    if "-h" in args or "--help" in args:
        return None
    request, positional = StaticRequest(), []
    items = iter(args)
    for arg in items:
        if arg not in _NUMBERS and arg not in _FRAMES:
            positional.append(arg)
            continue
        value = next(items, None)
        if value is None:
            raise Tf2ArgumentError(f"{arg} needs a value")
        if arg in _FRAMES:
            setattr(request, arg[2:].replace("-", "_"), value)
        else:
            request.values[arg] = _number(arg, value)
    given = set(request.values)
    if given & {"--qx", "--qy", "--qz", "--qw"} and given & {"--roll", "--pitch", "--yaw"}:
        raise Tf2ArgumentError("give the rotation as a quaternion or as roll/pitch/yaw, not both")
    if len(positional) in (8, 9):
        if given or request.frame_id or request.child_frame_id:
            raise Tf2ArgumentError("old-style positional arguments cannot be mixed with flags")
        names = ("--x", "--y", "--z", "--yaw", "--pitch", "--roll") if len(positional) == 8 else (
            "--x", "--y", "--z", "--qx", "--qy", "--qz", "--qw")  # fmt: skip
        for name, text in zip(names, positional, strict=False):
            request.values[name] = _number(name.lstrip("-"), text)
        request.frame_id, request.child_frame_id = positional[-2], positional[-1]
        request.old_style = True
    elif positional:
        raise Tf2ArgumentError(
            f"unexpected argument{'s' if len(positional) > 1 else ''} "
            f"{' '.join(positional)!r} (flags, or 8 or 9 positional values; see --help)"
        )
    if not request.frame_id:
        raise Tf2ArgumentError("no parent frame: give --frame-id FRAME_ID (see --help)")
    if not request.child_frame_id:
        raise Tf2ArgumentError("no child frame: give --child-frame-id CHILD_FRAME_ID (see --help)")
    if request.frame_id == request.child_frame_id:
        raise Tf2ArgumentError(
            f"cannot publish a static transform from '{request.frame_id}' to itself"
        )
    return request


def node_name() -> str:
    """``static_transform_publisher_`` and 16 random letters and digits."""
    chars = string.digits + string.ascii_letters
    return "static_transform_publisher_" + "".join(random.choices(chars, k=16))


def main(args: list[str] | None = None) -> int:
    """Run the program (``rosl run tf2_ros static_transform_publisher ...``)."""
    request = parse(user_args(args))
    if request is None:
        print(USAGE)
        return 0

    def body(node: Any) -> None:
        import rosl

        if request.old_style:
            node.get_logger().warning(
                "old-style arguments are deprecated; see --help for the flags (--x ... --frame-id)"
            )
        _publish(node, request)
        rosl.spin(node)

    return run(args, node_name(), body)


def _publish(node: Any, request: StaticRequest) -> None:
    from rosl.node.parameters import Descriptor
    from rosl.tf2.broadcaster import StaticTransformBroadcaster
    from rosl.tf2.messages import stamped

    transform = request.transform()
    read_only = Descriptor(read_only=True)
    for name, value in (*zip(("translation.x", "translation.y", "translation.z"),
                             transform.translation, strict=True),
                        *zip(("rotation.x", "rotation.y", "rotation.z", "rotation.w"),
                             transform.rotation, strict=True),
                        ("frame_id", request.frame_id),
                        ("child_frame_id", request.child_frame_id)):  # fmt: skip
        node.declare_parameter(name, value, read_only)
    message = stamped(transform, request.frame_id, request.child_frame_id,
                      node.get_clock().now().nanoseconds)  # fmt: skip
    node.static_broadcaster = StaticTransformBroadcaster(node)
    node.static_broadcaster.sendTransform(message)
    t, q = transform.translation, transform.rotation
    node.get_logger().info(
        "Spinning until stopped - publishing transform\n"
        f"translation: ('{t[0]:f}', '{t[1]:f}', '{t[2]:f}')\n"
        f"rotation: ('{q[0]:f}', '{q[1]:f}', '{q[2]:f}', '{q[3]:f}')\n"
        f"from '{request.frame_id}' to '{request.child_frame_id}'"
    )


__all__ = ["USAGE", "StaticRequest", "main", "node_name", "parse"]
