"""tf2_geometry_msgs: geometry_msgs data moved by a TransformStamped.

``do_transform_point`` / ``_vector3`` / ``_pose`` / ``_pose_stamped`` /
``_pose_with_covariance_stamped`` / ``_polygon_stamped`` as in Humble and Jazzy. The
result's header is the transform's (its frame is the target frame). ``do_transform_pose``
takes a ``Pose`` (Humble's and Jazzy's signature) and also the ``PoseStamped`` older code
passes, returning the same kind it was given; point and vector accept the unstamped
message too. Importing this module registers the stamped types with ``Buffer.transform``.
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

from rosl.tf2.messages import message_class, transform_of
from rosl.tf2.registration import ConvertRegistration, TransformRegistration
from rosl.tf2.transform import Transform, qmul, rotate, rotation_matrix


def _header(transform: Any) -> Any:
    return copy.deepcopy(transform.header)


def _vector_like(msg: Any, field: str, name: str, move: Any) -> Any:
    """``msg`` (a ``<name>Stamped`` with ``field``, or a plain ``<name>``) moved by ``move``."""
    inner = getattr(msg, field, None)
    source = msg if inner is None else inner
    x, y, z = move((source.x, source.y, source.z))
    if inner is None:
        return message_class(f"geometry_msgs/msg/{name}")(x=x, y=y, z=z)
    result = message_class(f"geometry_msgs/msg/{name}Stamped")()
    target = getattr(result, field)
    target.x, target.y, target.z = x, y, z
    return result


def do_transform_point(point: Any, transform: Any) -> Any:
    """A PointStamped (or Point) expressed in the transform's frame."""
    result = _vector_like(point, "point", "Point", transform_of(transform).apply)
    if hasattr(result, "header"):
        result.header = _header(transform)
    return result


def do_transform_vector3(vector3: Any, transform: Any) -> Any:
    """A Vector3Stamped (or Vector3) turned by the transform's rotation (no translation)."""
    rotation = transform_of(transform).rotation
    result = _vector_like(vector3, "vector", "Vector3", lambda v: rotate(rotation, v))
    if hasattr(result, "header"):
        result.header = _header(transform)
    return result


def _pose(pose: Any, transform: Any) -> Any:
    t = transform_of(transform)
    p, o = pose.position, pose.orientation
    position = t.apply((p.x, p.y, p.z))
    q = qmul(t.rotation, (o.x, o.y, o.z, o.w))
    norm = sum(v * v for v in q) ** 0.5 or 1.0
    sign = -1.0 if q[3] < 0 else 1.0
    result = message_class("geometry_msgs/msg/Pose")()
    result.position.x, result.position.y, result.position.z = position
    o = result.orientation
    o.x, o.y, o.z, o.w = (sign * v / norm for v in q)
    return result


def do_transform_pose(pose: Any, transform: Any) -> Any:
    """A Pose in the transform's frame (a PoseStamped gives a PoseStamped, as before Humble)."""
    if hasattr(pose, "header") and hasattr(pose, "pose"):
        return do_transform_pose_stamped(pose, transform)
    return _pose(pose, transform)


def do_transform_pose_stamped(pose: Any, transform: Any) -> Any:
    """A PoseStamped in the transform's frame."""
    result = message_class("geometry_msgs/msg/PoseStamped")()
    result.pose = _pose(pose.pose, transform)
    result.header = _header(transform)
    return result


def transform_covariance(cov_in: Any, transform: Any) -> Any:
    """A 6x6 pose covariance (row-major, 36 values) rotated into the transform's frame."""
    r = np.array(rotation_matrix(transform_of(transform).rotation))
    cov = np.asarray(cov_in, dtype=float).reshape(6, 6)
    out = np.zeros((6, 6))
    for i in (0, 3):
        for j in (0, 3):
            out[i : i + 3, j : j + 3] = r @ cov[i : i + 3, j : j + 3] @ r.T
    return out.reshape(36)


def do_transform_pose_with_covariance_stamped(pose: Any, transform: Any) -> Any:
    """A PoseWithCovarianceStamped in the transform's frame, covariance rotated too."""
    result = message_class("geometry_msgs/msg/PoseWithCovarianceStamped")()
    result.pose.pose = _pose(pose.pose.pose, transform)
    result.pose.covariance = transform_covariance(pose.pose.covariance, transform)
    result.header = _header(transform)
    return result


def do_transform_polygon_stamped(polygon: Any, transform: Any) -> Any:
    """A PolygonStamped with every point in the transform's frame."""
    t: Transform = transform_of(transform)
    point32 = message_class("geometry_msgs/msg/Point32")
    result = message_class("geometry_msgs/msg/PolygonStamped")()
    for p in polygon.polygon.points:
        x, y, z = t.apply((p.x, p.y, p.z))
        result.polygon.points.append(point32(x=x, y=y, z=z))
    result.header = _header(transform)
    return result


def _same(msg: Any) -> Any:
    return msg


def register() -> None:
    """Tell Buffer.transform and convert() about the geometry_msgs types."""
    transforms = TransformRegistration()
    for name, function in (
        ("PointStamped", do_transform_point),
        ("Vector3Stamped", do_transform_vector3),
        ("PoseStamped", do_transform_pose_stamped),
        ("PoseWithCovarianceStamped", do_transform_pose_with_covariance_stamped),
        ("PolygonStamped", do_transform_polygon_stamped),
    ):
        transforms.add(message_class(f"geometry_msgs/msg/{name}"), function)
    converts = ConvertRegistration()
    for name in ("Vector3Stamped", "PoseStamped", "PointStamped"):
        converts.add_to_msg(message_class(f"geometry_msgs/msg/{name}"), _same)
        converts.add_from_msg(message_class(f"geometry_msgs/msg/{name}"), _same)


register()

__all__ = [
    "do_transform_point",
    "do_transform_polygon_stamped",
    "do_transform_pose",
    "do_transform_pose_stamped",
    "do_transform_pose_with_covariance_stamped",
    "do_transform_vector3",
    "transform_covariance",
]
