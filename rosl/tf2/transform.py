"""Rigid transforms: a translation and a unit quaternion, composed, inverted and interpolated.

Plain floats, no numpy (a lookup composes a handful of these). The rotation matrix and the
Euler angles follow tf2's ``Matrix3x3`` (``setRotation``, ``getEulerYPR``), so tf2_echo's
text comes out digit for digit, signed zeros included.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]  # x, y, z, w
Matrix = tuple[Vector, Vector, Vector]

IDENTITY_ROTATION: Quaternion = (0.0, 0.0, 0.0, 1.0)


def qmul(a: Quaternion, b: Quaternion) -> Quaternion:
    """The Hamilton product ``a * b`` (apply ``b``, then ``a``)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by + ay * bw + az * bx - ax * bz,
        aw * bz + az * bw + ax * by - ay * bx,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def rotation_matrix(q: Quaternion) -> Matrix:
    """The 3x3 rotation of ``q`` (scaled by its norm, as tf2's ``Matrix3x3::setRotation``)."""
    x, y, z, w = q
    d = x * x + y * y + z * z + w * w
    s = 2.0 / d if d else 0.0
    xs, ys, zs = x * s, y * s, z * s
    wx, wy, wz = w * xs, w * ys, w * zs
    xx, xy, xz = x * xs, x * ys, x * zs
    yy, yz, zz = y * ys, y * zs, z * zs
    return (
        (1.0 - (yy + zz), xy - wz, xz + wy),
        (xy + wz, 1.0 - (xx + zz), yz - wx),
        (xz - wy, yz + wx, 1.0 - (xx + yy)),
    )


def rotate(q: Quaternion, v: Vector) -> Vector:
    """``v`` turned by ``q``."""
    m = rotation_matrix(q)
    return (
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    )


def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> Quaternion:
    """Fixed-axis roll (x), then pitch (y), then yaw (z), in radians, as one quaternion."""
    about_x = (math.sin(roll / 2), 0.0, 0.0, math.cos(roll / 2))
    about_y = (0.0, math.sin(pitch / 2), 0.0, math.cos(pitch / 2))
    about_z = (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
    return qmul(about_z, qmul(about_y, about_x))


def quaternion_from_matrix(m: Matrix) -> Quaternion:
    """A unit quaternion with ``w >= 0`` for the rotation matrix ``m``."""
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0.0:
        s = math.sqrt(trace + 1.0) * 2.0
        q = ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, s / 4)
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]) * 2.0
        q = (s / 4, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s)
    elif m[1][1] > m[2][2]:
        s = math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]) * 2.0
        q = ((m[0][1] + m[1][0]) / s, s / 4, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s)
    else:
        s = math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]) * 2.0
        q = ((m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, s / 4, (m[1][0] - m[0][1]) / s)
    return (-q[0], -q[1], -q[2], -q[3]) if q[3] < 0 else q


def slerp(a: Quaternion, b: Quaternion, ratio: float) -> Quaternion:
    """Spherical interpolation from ``a`` (ratio 0) to ``b`` (ratio 1), the short way round."""
    dot = sum(p * q for p, q in zip(a, b, strict=True))
    if dot < 0.0:
        b, dot = (-b[0], -b[1], -b[2], -b[3]), -dot
    if dot > 1.0 - 1e-12:  # the same rotation: nothing to interpolate
        return a
    theta = math.acos(min(1.0, dot))
    sin_theta = math.sin(theta)
    wa, wb = math.sin((1.0 - ratio) * theta) / sin_theta, math.sin(ratio * theta) / sin_theta
    return (
        wa * a[0] + wb * b[0],
        wa * a[1] + wb * b[1],
        wa * a[2] + wb * b[2],
        wa * a[3] + wb * b[3],
    )


@dataclass(frozen=True, slots=True)
class Transform:
    """A rigid transform: rotate by ``rotation``, then move by ``translation``."""

    translation: Vector = (0.0, 0.0, 0.0)
    rotation: Quaternion = IDENTITY_ROTATION

    def __mul__(self, other: Transform) -> Transform:
        """``self`` then ``other`` (parent←a times a←b gives parent←b)."""
        if other.translation == (0.0, 0.0, 0.0) and other.rotation == IDENTITY_ROTATION:
            return self
        (x, y, z), (dx, dy, dz) = self.translation, rotate(self.rotation, other.translation)
        return Transform((x + dx, y + dy, z + dz), qmul(self.rotation, other.rotation))

    def inverse(self) -> Transform:
        """The transform going the other way."""
        x, y, z, w = self.rotation
        norm = x * x + y * y + z * z + w * w or 1.0
        inverse: Quaternion = (-x / norm, -y / norm, -z / norm, w / norm)
        back = rotate(inverse, self.translation)
        return Transform((-back[0], -back[1], -back[2]), inverse)

    def apply(self, point: Vector) -> Vector:
        """``point`` moved by this transform (rotation, then translation)."""
        rx, ry, rz = rotate(self.rotation, point)
        x, y, z = self.translation
        return (rx + x, ry + y, rz + z)

    def interpolate(self, later: Transform, ratio: float) -> Transform:
        """Linear in translation, slerp in rotation (ratio 0 is ``self``, 1 is ``later``)."""
        t = tuple(a + (b - a) * ratio for a, b in zip(self.translation, later.translation,
                                                       strict=True))  # fmt: skip
        return Transform((t[0], t[1], t[2]), slerp(self.rotation, later.rotation, ratio))

    def matrix(self) -> Matrix:
        """The rotation as a 3x3 matrix."""
        return rotation_matrix(self.rotation)

    def euler(self) -> Vector:
        """Roll, pitch, yaw in radians, as tf2's ``Matrix3x3::getEulerYPR`` gives them."""
        m = self.matrix()
        if abs(m[2][0]) >= 1.0:  # gimbal lock: pitch is plus or minus a quarter turn
            delta = math.atan2(m[2][1], m[2][2])
            return (delta, math.pi / 2 if m[2][0] < 0 else -math.pi / 2, 0.0)
        pitch = -math.asin(m[2][0])
        cos_pitch = math.cos(pitch)
        roll = math.atan2(m[2][1] / cos_pitch, m[2][2] / cos_pitch)
        yaw = math.atan2(m[1][0] / cos_pitch, m[0][0] / cos_pitch)
        return (roll, pitch, yaw)

    def rpy(self) -> Vector:
        """Roll, pitch, yaw in radians (the same angles as :meth:`euler`)."""
        return self.euler()


__all__ = [
    "Matrix",
    "Quaternion",
    "Transform",
    "Vector",
    "qmul",
    "quaternion_from_matrix",
    "quaternion_from_rpy",
    "rotate",
    "rotation_matrix",
    "slerp",
]
