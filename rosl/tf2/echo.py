"""``tf2_echo``: print the transform between two frames, once per period, as tf2_echo does.

``tf2_echo SOURCE TARGET [RATE]`` (Humble's form) and the newer ``-r RATE``, ``-t TIME``
(look up at that fixed time, in seconds) and ``-p PRECISION``. Each block gives the pose of
TARGET in SOURCE: the time, translation, quaternion, roll/pitch/yaw in radians and degrees
and the 4x4 matrix, with tf2_echo's digits (its unpadded nanoseconds and signed zeros too).
While the transform is not there yet it says why, at most once a second. The quaternion line
reads as Humble's unless ``ROS_DISTRO`` names Jazzy or later, which add ``(xyzw)``.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosl.tf2.errors import Tf2ArgumentError, TransformException
from rosl.tf2.program import run, spin_for, user_args

if TYPE_CHECKING:
    from rosl.tf2.transform import Transform

USAGE = """\
usage: tf2_echo SOURCE_FRAME TARGET_FRAME [RATE] [-r RATE] [-t TIME] [-p PRECISION]

Prints the pose of TARGET_FRAME in SOURCE_FRAME (the transform that takes data from
TARGET_FRAME into SOURCE_FRAME), RATE times a second (default 1).
  -r RATE       prints per second
  -t TIME       look up at this fixed time (seconds) instead of the latest
  -p PRECISION  decimals printed (default 3)"""


@dataclass(slots=True)
class EchoRequest:
    """What tf2_echo's command line asked for."""

    source: str
    target: str
    rate: float = 1.0
    time_ns: int = 0
    precision: int = 3


def _value(flag: str, text: str | None, kind: type[float] | type[int]) -> float:
    if text is None:
        raise Tf2ArgumentError(f"{flag} needs a value")
    try:
        return kind(text)
    except ValueError:
        what = "an integer" if kind is int else "a number"
        raise Tf2ArgumentError(f"{flag}: '{text}' is not {what}") from None


def parse(args: list[str]) -> EchoRequest | None:
    """The request in ``args`` (without the program name); None when help was asked for.

    Raises:
        Tf2ArgumentError: frames missing, an unknown option, a bad rate, time or precision.
    """
    if "-h" in args or "--help" in args:
        return None
    positional: list[str] = []
    options: dict[str, float] = {}
    items = iter(args)
    for arg in items:
        if arg in ("-r", "-t", "-p"):
            options[arg] = _value(arg, next(items, None), int if arg == "-p" else float)
        elif arg.startswith("-") and len(arg) > 1 and not _is_number(arg):
            raise Tf2ArgumentError(f"unknown option {arg} (see --help)")
        else:
            positional.append(arg)
    if len(positional) < 2:
        raise Tf2ArgumentError("give SOURCE_FRAME and TARGET_FRAME (see --help)")
    if len(positional) > 3:
        raise Tf2ArgumentError(f"unexpected arguments {' '.join(positional[3:])!r} (see --help)")
    request = EchoRequest(positional[0], positional[1])
    if len(positional) == 3:
        request.rate = _value("rate", positional[2], float)
    request.rate = options.get("-r", request.rate)
    if not request.rate > 0 or math.isinf(request.rate):
        raise Tf2ArgumentError(f"the rate must be a positive number of prints per second, "
                               f"not {request.rate:g}")  # fmt: skip
    if "-t" in options:
        if options["-t"] < 0:
            raise Tf2ArgumentError("-t: the time must not be negative")
        request.time_ns = round(options["-t"] * 1e9)
    request.precision = int(options.get("-p", 3))
    if request.precision < 0:
        raise Tf2ArgumentError("-p: the precision must not be negative")
    return request


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


HUMBLE_AND_OLDER = ("", "humble", "galactic", "foxy", "eloquent", "dashing")


def quaternion_label() -> str:
    """How tf2_echo names the quaternion line: Jazzy and later add ``(xyzw)``.

    ``ROS_DISTRO`` chooses, as for bags; unset, rosl prints what Humble prints.
    """
    newer = os.environ.get("ROS_DISTRO", "").strip().lower() not in HUMBLE_AND_OLDER
    return "in Quaternion (xyzw)" if newer else "in Quaternion"


def echo_text(transform: Transform, stamp_ns: int, precision: int = 3) -> str:
    """tf2_echo's block for a transform at ``stamp_ns``."""
    p = precision
    roll, pitch, yaw = transform.euler()
    matrix = transform.matrix()
    rows = [(*matrix[i], transform.translation[i]) for i in range(3)] + [(0.0, 0.0, 0.0, 1.0)]
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)

    def listed(values: tuple[float, ...]) -> str:
        return "[" + ", ".join(f"{v:.{p}f}" for v in values) + "]"

    return "\n".join(
        [
            f"At time {sec}.{nanosec}",
            f"- Translation: {listed(transform.translation)}",
            f"- Rotation: {quaternion_label()} {listed(transform.rotation)}",
            f"- Rotation: in RPY (radian) {listed((roll, pitch, yaw))}",
            f"- Rotation: in RPY (degree) "
            f"{listed(tuple(math.degrees(a) for a in (roll, pitch, yaw)))}",
            "- Matrix:",
            *("".join(f" {v:6.{p}f}" for v in row) for row in rows),
        ]
    )


def main(args: list[str] | None = None) -> int:
    """Run the program (``rosl run tf2_ros tf2_echo SOURCE TARGET``)."""
    request = parse(user_args(args))
    if request is None:
        print(USAGE)
        return 0
    return run(args, "tf2_echo", lambda node: _run(node, request))


def _run(node: Any, request: EchoRequest) -> None:
    import rosl
    from rosl.tf2.buffer import Buffer
    from rosl.tf2.listener import TransformListener
    from rosl.tf2.messages import transform_of

    buffer = Buffer(node=node)
    node.tf_listener = TransformListener(buffer, node)
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    period = 1.0 / request.rate
    stamp = rosl.Time(nanoseconds=request.time_ns)
    logger, said = node.get_logger(), -math.inf
    while rosl.ok():
        possible, why = buffer.can_transform_core(request.source, request.target, stamp)
        if possible:
            break
        if time.monotonic() - said >= 1.0:
            said = time.monotonic()
            logger.info(f"Waiting for transform {request.source} ->  {request.target}: {why}")
        spin_for(executor, period)
    while rosl.ok():
        try:
            found = buffer.lookup_transform_core(request.source, request.target, stamp)
            text = echo_text(transform_of(found), found.header.stamp.sec * 1_000_000_000
                             + found.header.stamp.nanosec, request.precision)  # fmt: skip
        except TransformException as err:
            text = (f"Failure at {time.time():f}\nException thrown:{err}\n"
                    f"The current list of frames is:\n{buffer.all_frames_as_string()}")  # fmt: skip
        print(text, flush=True)
        spin_for(executor, period)


__all__ = ["USAGE", "EchoRequest", "echo_text", "main", "parse"]
