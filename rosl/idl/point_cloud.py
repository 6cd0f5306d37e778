"""sensor_msgs/msg/PointCloud2 as numpy: the operations of ROS 2's ``sensor_msgs_py``.

A cloud's points are read as one structured numpy array laid over the message's bytes (its
``PointField`` list gives names, types and offsets), and a cloud is built from a structured
array, a plain 2-D array or a list of tuples with one copy — never a loop over points in
Python, except for the list forms that ask for Python objects (``read_points_list``, a list
given to ``create_cloud``). ``sensor_msgs_py.point_cloud2`` re-exports these names.
"""

from __future__ import annotations

import sys
from collections import namedtuple
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.lib import recfunctions

from rosl.idl.errors import PointCloudError
from rosl.idl.registry import get_message_class

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

__all__ = [
    "DATATYPES",
    "DUMMY_FIELD_PREFIX",
    "create_cloud",
    "create_cloud_xyz32",
    "dtype_from_fields",
    "read_points",
    "read_points_list",
    "read_points_numpy",
]

# PointField.datatype -> numpy type (the constants INT8=1 ... FLOAT64=8)
DATATYPES: dict[int, type[np.generic]] = {
    1: np.int8,
    2: np.uint8,
    3: np.int16,
    4: np.uint16,
    5: np.int32,
    6: np.uint32,
    7: np.float32,
    8: np.float64,
}
_CLOUD = "sensor_msgs/msg/PointCloud2"
DUMMY_FIELD_PREFIX = "unnamed_field"  # the name of a field that has none: unnamed_field_<index>


def dtype_from_fields(fields: Iterable[Any], point_step: int | None = None) -> np.dtype[Any]:
    """Return the structured dtype of one point described by ``PointField`` messages.

    A field without a name is called ``unnamed_field_<index>``; a field of ``count`` N > 1
    becomes N fields ``<name>_0`` ... ``<name>_<N-1>``, as sensor_msgs_py names them.
    ``point_step`` pads the dtype to the cloud's point size.

    Raises:
        PointCloudError: an unknown datatype, a count of 0, or two fields of one name.
    """
    names: list[str] = []
    formats: list[Any] = []
    offsets: list[int] = []
    for index, field in enumerate(fields):
        name = field.name or f"{DUMMY_FIELD_PREFIX}_{index}"
        if field.datatype not in DATATYPES:
            raise PointCloudError(
                f"PointCloud2 field '{name}': datatype {field.datatype} is not one of "
                "PointField's INT8 (1) to FLOAT64 (8)"
            )
        if field.count < 1:
            raise PointCloudError(f"PointCloud2 field '{name}': a count of 0 holds no value")
        base = np.dtype(DATATYPES[field.datatype])
        for part in range(field.count):
            part_name = f"{name}_{part}" if field.count > 1 else name
            if part_name in names:
                raise PointCloudError(f"PointCloud2: two fields are named '{part_name}'")
            names.append(part_name)
            formats.append(base)
            offsets.append(int(field.offset) + part * base.itemsize)
    layout: dict[str, Any] = {"names": names, "formats": formats, "offsets": offsets}
    if point_step is not None:
        layout["itemsize"] = int(point_step)
    try:
        result: np.dtype[Any] = np.dtype(layout)  # type: ignore[call-overload]
    except ValueError as err:
        raise PointCloudError(f"PointCloud2 fields do not fit in a point: {err}") from None
    return result


def read_points(
    cloud: Any,
    field_names: Sequence[str] | None = None,
    skip_nans: bool = False,
    uvs: Iterable[Any] | None = None,
    reshape_organized_cloud: bool = False,
) -> np.ndarray[Any, Any]:
    """Return a cloud's points as a structured numpy array (a view of its data: no copy).

    Args:
        cloud: a sensor_msgs/msg/PointCloud2.
        field_names: the fields to keep (all when None).
        skip_nans: drop points with a NaN in any kept field (unless the cloud says it is dense).
        uvs: indices of the points to return.
        reshape_organized_cloud: shape (width, height) when the cloud has several rows, as
            sensor_msgs_py shapes it (``create_cloud`` of an (a, b) array has width a).

    Raises:
        PointCloudError: not a PointCloud2, unknown field names, or too few bytes.
    """
    if getattr(cloud, "__msgtype__", None) != _CLOUD:
        raise PointCloudError(f"read_points expects a {_CLOUD}, got {type(cloud).__name__}")
    dtype = dtype_from_fields(cloud.fields, cloud.point_step or None)
    count = int(cloud.width) * int(cloud.height)
    data = np.asarray(cloud.data, dtype=np.uint8)
    if data.size < count * dtype.itemsize:
        raise PointCloudError(
            f"PointCloud2 holds {data.size} bytes of data, fewer than its {count} points of "
            f"{dtype.itemsize} bytes each"
        )
    points = np.frombuffer(data, dtype=dtype, count=count)
    if field_names is not None:
        missing = [n for n in field_names if n not in (dtype.names or ())]
        if missing:
            raise PointCloudError(
                f"PointCloud2 has no field '{missing[0]}'; its fields are: "
                + ", ".join(dtype.names or ())
            )
        points = points[list(field_names)]
    if bool(cloud.is_bigendian) != (sys.byteorder == "big"):  # values in this machine's order
        points = points.view(points.dtype.newbyteorder()).astype(points.dtype)
    if skip_nans and not cloud.is_dense and len(points):
        keep = np.ones(len(points), dtype=bool)
        for name in points.dtype.names or ():
            column = points[name]
            if column.dtype.kind == "f":
                keep &= ~np.isnan(column)
        points = points[keep]
    if uvs is not None:
        index = uvs if isinstance(uvs, np.ndarray) else np.fromiter(uvs, dtype=np.int64)
        points = points[index]
    if reshape_organized_cloud and cloud.height > 1:
        points = points.reshape(int(cloud.width), int(cloud.height))
    return points


def read_points_numpy(
    cloud: Any,
    field_names: Sequence[str] | None = None,
    skip_nans: bool = False,
    uvs: Iterable[Any] | None = None,
    reshape_organized_cloud: bool = False,
) -> np.ndarray[Any, Any]:
    """Return the points as a plain 2-D array (one column per field; fields of one type).

    Raises:
        PointCloudError: the fields read have different datatypes.
    """
    wanted = [f for f in cloud.fields if field_names is None or f.name in field_names]
    if len({f.datatype for f in wanted}) > 1:
        raise PointCloudError(
            "read_points_numpy needs fields of one datatype; use read_points for mixed ones"
        )
    points = read_points(cloud, field_names, skip_nans, uvs, reshape_organized_cloud)
    return recfunctions.structured_to_unstructured(points)


def read_points_list(
    cloud: Any,
    field_names: Sequence[str] | None = None,
    skip_nans: bool = False,
    uvs: Iterable[Any] | None = None,
) -> list[Any]:
    """Return the points as a list of namedtuples ``Point(x=..., y=..., ...)``."""
    points = read_points(cloud, field_names, skip_nans, uvs)
    factory: Any = namedtuple  # field names known only at run time
    point = factory("Point", points.dtype.names or (), rename=True)
    return [point._make(p) for p in points.tolist()]


def create_cloud(
    header: Any, fields: Sequence[Any], points: Any, point_step: int | None = None
) -> Any:
    """Build a sensor_msgs/msg/PointCloud2 from points.

    Args:
        header: the cloud's std_msgs/msg/Header.
        fields: its sensor_msgs/msg/PointField list.
        points: a structured array whose dtype is ``dtype_from_fields(fields, point_step)``;
            a plain array of shape (N, values) or (width, height, values) when all fields
            share one datatype; or an iterable of per-point tuples. A 2-D structured array
            (width, height) is an organized cloud, as sensor_msgs_py lays it out.
        point_step: bytes per point (default: the end of the last field).

    Raises:
        PointCloudError: points that do not match the fields.
    """
    dtype = dtype_from_fields(fields, point_step)
    if isinstance(points, np.ndarray) and points.dtype.names is None:
        kinds = {f.datatype for f in fields}
        if len(kinds) != 1:
            raise PointCloudError(
                "create_cloud: a plain array needs fields of one datatype; "
                "pass a structured array for mixed ones"
            )
        columns = len(dtype.names or ())
        if points.ndim < 2 or points.shape[-1] != columns:
            raise PointCloudError(
                f"create_cloud: points of shape {points.shape} do not have one column for "
                f"each of the {columns} values of a point"
            )
        points = recfunctions.unstructured_to_structured(points, dtype=dtype)
    elif isinstance(points, np.ndarray):
        if points.dtype != dtype:
            raise PointCloudError(
                f"create_cloud: the points' dtype {points.dtype} does not match the PointFields' "
                f"{dtype} (names, order, types and point_step must agree)"
            )
    else:
        try:
            points = np.array([tuple(p) for p in points], dtype=dtype)
        except (TypeError, ValueError) as err:
            raise PointCloudError(
                f"create_cloud: the points do not match the fields ({err})"
            ) from None
    if points.ndim > 2:
        raise PointCloudError("create_cloud: an organized cloud has at most two dimensions")
    width, height = (len(points), 1) if points.ndim == 1 else points.shape  # sensor_msgs_py's
    data = np.ascontiguousarray(points).view(np.uint8).reshape(-1)
    if np.may_share_memory(data, points):
        data = data.copy()  # the message owns its bytes, as in rclpy
    cloud_class = get_message_class(_CLOUD)
    return cloud_class(
        header=header,
        height=height,
        width=width,
        fields=list(fields),
        is_bigendian=sys.byteorder != "little",
        point_step=dtype.itemsize,
        row_step=dtype.itemsize * width,
        data=data,
        is_dense=False,
    )


def create_cloud_xyz32(header: Any, points: Any) -> Any:
    """Build a PointCloud2 of float32 ``x``, ``y``, ``z`` from (N, 3) or (width, height, 3)."""
    field_class = get_message_class("sensor_msgs/msg/PointField")
    fields = [field_class(name=n, offset=4 * i, datatype=7, count=1) for i, n in enumerate("xyz")]
    values = np.asarray(points, dtype=np.float32)
    return create_cloud(header, fields, values if values.ndim > 1 else values.reshape(-1, 3))
