"""CDR bytes of the simulator's high-rate messages, packed directly with ``struct``.

Hand-written because the generic path (message object, then rosbags' serializer, which
looks up every nested definition on each call) costs ~18-45 us a message, and the sim sends
~200 messages per simulated second: that alone would cap it near 100x real time. The sim's
messages have fixed frame names and sizes, so each kind gets one ``struct`` format (strings
and alignment padding baked in) built once, and a message is one ``pack`` call. The bytes are
the ones rosbags gives for the same message (a test compares them over many states).

Little-endian CDR with the 4-byte encapsulation header; every primitive is aligned to its
size, counted from the end of that header.
"""

from __future__ import annotations

import struct
from functools import cache
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Sequence

    import numpy as np
else:
    from rosl.idl.lazy_numpy import np

HEADER = b"\x00\x01\x00\x00"
NS = 1_000_000_000


class _Layout:
    """Builds a struct format, tracking the CDR offset for alignment."""

    def __init__(self) -> None:
        self.format = "<"
        self.offset = 0

    def align(self, size: int) -> None:
        pad = -self.offset % size
        if pad:
            self.format += f"{pad}x"
            self.offset += pad

    def field(self, code: str, size: int, count: int = 1) -> None:
        self.align(size)
        self.format += f"{count}{code}" if count != 1 else code
        self.offset += size * count

    def string(self, text: bytes) -> None:
        """A string field: its length (uint32) and its bytes with the closing NUL."""
        self.align(4)
        self.format += f"I{len(text) + 1}s"
        self.offset += 4 + len(text) + 1

    def struct(self) -> struct.Struct:
        return struct.Struct(self.format)


def _split_secs(now_ns: int) -> tuple[int, int]:
    return divmod(now_ns, NS)


CLOCK = struct.Struct("<4siI")  # header, sec, nanosec


def clock(now_ns: int) -> bytes:
    """rosgraph_msgs/msg/Clock."""
    sec, nanosec = _split_secs(now_ns)
    return CLOCK.pack(HEADER, sec, nanosec)


COVARIANCE_SIZE = 36 * 8


@cache
def odometry_struct(frame: bytes, child: bytes) -> struct.Struct:
    """nav_msgs/msg/Odometry for fixed frames as one format.

    Its values: the encapsulation header, sec, nanosec, the two frames (each its size with
    the NUL, then the bytes), the pose (7 doubles), the pose covariance (288 packed bytes),
    the twist (6 doubles) and the twist covariance (288 bytes): the doubles are contiguous
    from the 8-aligned pose on, so no padding follows it.
    """
    layout = _Layout()
    layout.format += "4s"  # the encapsulation header (not counted in offsets)
    layout.field("i", 4)
    layout.field("I", 4)
    layout.string(frame)
    layout.string(child)
    layout.field("d", 8, 7)
    return struct.Struct(f"{layout.format}{COVARIANCE_SIZE}s6d{COVARIANCE_SIZE}s")


def odometry(now_ns: int, frame: bytes, child: bytes, pose: Sequence[float],
             covariance: Sequence[float], twist: Sequence[float]) -> bytes:  # fmt: skip
    """nav_msgs/msg/Odometry.

    ``pose`` is x, y, z, qx, qy, qz, qw; ``twist`` 6 values; the same 36 ``covariance``
    values go with the pose and the twist.
    """
    sec, nanosec = divmod(now_ns, NS)
    packed = struct.pack("<36d", *covariance)
    return odometry_struct(frame, child).pack(
        HEADER, sec, nanosec, len(frame) + 1, frame, len(child) + 1, child, *pose, packed,
        *twist, packed,
    )  # fmt: skip


@cache
def tf_struct(frames: tuple[tuple[bytes, bytes], ...]) -> struct.Struct:
    """tf2_msgs/msg/TFMessage of transforms between these (parent, child) frames.

    Its values: the encapsulation header, the count, then per transform sec, nanosec, the
    parent's size and bytes, the child's, and 7 doubles (x, y, z, qx, qy, qz, qw).
    """
    layout = _Layout()
    layout.format += "4s"
    layout.field("I", 4)
    for parent, child in frames:
        layout.field("i", 4)
        layout.field("I", 4)
        layout.string(parent)
        layout.string(child)
        layout.field("d", 8, 7)
    return layout.struct()


def tf_message(now_ns: int, transforms: Sequence[tuple[bytes, bytes, Sequence[float]]]) -> bytes:
    """tf2_msgs/msg/TFMessage of (parent, child, (x, y, z, qx, qy, qz, qw)) transforms."""
    sec, nanosec = _split_secs(now_ns)
    values: list[object] = [HEADER, len(transforms)]
    for parent, child, numbers in transforms:
        values += [sec, nanosec, len(parent) + 1, parent, len(child) + 1, child, *numbers]
    return tf_struct(tuple((p, c) for p, c, _ in transforms)).pack(*values)


@cache
def joint_struct(names: tuple[bytes, ...], count: int | None = None) -> struct.Struct:
    """sensor_msgs/msg/JointState of these joints, an empty frame and no efforts.

    Its values: the encapsulation header, sec, nanosec, 1, b"", the count, each name's size
    and bytes, then the positions and the velocities (each its count, then the doubles), 0.
    ``count``: how many positions and velocities (default: one per name).
    """
    return _joint_layout(names, len(names) if count is None else count)[0].struct()


@cache
def joint_offsets(names: tuple[bytes, ...], count: int) -> tuple[int, int]:
    """Where the positions' and the velocities' doubles start in :func:`joint_struct`'s bytes."""
    return _joint_layout(names, count)[1]


def _joint_layout(names: tuple[bytes, ...], count: int) -> tuple[_Layout, tuple[int, int]]:
    layout = _Layout()
    layout.format += "4s"
    layout.field("i", 4)
    layout.field("I", 4)
    layout.string(b"")
    layout.field("I", 4)
    for name in names:
        layout.string(name)
    offsets = []
    for _ in range(2):  # position, velocity
        layout.field("I", 4)
        if count:
            layout.align(8)
        offsets.append(len(HEADER) + layout.offset)  # counted in the bytes, header included
        if count:
            layout.field("d", 8, count)
    layout.field("I", 4)  # no efforts
    return layout, (offsets[0], offsets[1])


def joint_state(now_ns: int, names: Sequence[bytes], position: Sequence[float],
                velocity: Sequence[float]) -> bytes:  # fmt: skip
    """sensor_msgs/msg/JointState with an empty header frame and no efforts."""
    sec, nanosec = _split_secs(now_ns)
    values: list[object] = [HEADER, sec, nanosec, 1, b"", len(names)]
    for name in names:
        values += [len(name) + 1, name]
    values += [len(position), *position, len(velocity), *velocity, 0]
    return joint_struct(tuple(names), len(position)).pack(*values)


@cache
def _scan_layout(frame: bytes) -> struct.Struct:
    layout = _Layout()
    layout.format += "4s"
    layout.field("i", 4)
    layout.field("I", 4)
    layout.string(frame)
    layout.field("f", 4, 7)
    layout.field("I", 4)  # the ranges' count; the float32 data follows (aligned: offset % 4 == 0)
    return layout.struct()


_NO_INTENSITIES = struct.pack("<I", 0)


def laser_scan(now_ns: int, frame: bytes, fields: Sequence[float], ranges: np.ndarray) -> bytes:
    """sensor_msgs/msg/LaserScan with no intensities.

    ``fields`` are angle_min, angle_max, angle_increment, time_increment, scan_time,
    range_min, range_max; ``ranges`` are float32.
    """
    sec, nanosec = _split_secs(now_ns)
    head = _scan_layout(frame).pack(
        HEADER, sec, nanosec, len(frame) + 1, frame, *fields, len(ranges)
    )
    return head + ranges.astype("<f4", copy=False).tobytes() + _NO_INTENSITIES


class ScanPacker:
    """sensor_msgs/msg/LaserScan of one LiDAR, as :func:`laser_scan`, its fixed part packed once.

    Called with a scan's stamp and ranges (float32): the stamp and the count are written into
    the prepared head, which is joined with the ranges' bytes and the empty intensities.
    """

    def __init__(self, frame: bytes, fields: Sequence[float]) -> None:
        layout = _scan_layout(frame)
        self._head = bytearray(layout.pack(HEADER, 0, 0, len(frame) + 1, frame, *fields, 0))
        self._count = layout.size - 4  # where the ranges' count is

    def __call__(self, sec: int, nanosec: int, ranges: np.ndarray) -> bytes:
        """The scan stamped ``sec``, ``nanosec``, of these ranges, as CDR."""
        head = self._head
        _STAMP_INTO(head, len(HEADER), sec, nanosec)
        _COUNT_INTO(head, self._count, len(ranges))
        data = np.ascontiguousarray(ranges, dtype="<f4").data  # (the scan's own, no copy)
        return b"".join((head, data, _NO_INTENSITIES))


_STAMP_INTO = struct.Struct("<iI").pack_into
_COUNT_INTO = struct.Struct("<I").pack_into
