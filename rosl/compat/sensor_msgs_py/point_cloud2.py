"""sensor_msgs_py.point_cloud2: PointCloud2 to and from numpy (``rosl.idl.point_cloud``)."""

from rosl.idl.point_cloud import (
    DATATYPES,
    DUMMY_FIELD_PREFIX,
    create_cloud,
    create_cloud_xyz32,
    dtype_from_fields,
    read_points,
    read_points_list,
    read_points_numpy,
)

_DATATYPES = DATATYPES  # the name sensor_msgs_py's own code uses

__all__ = [
    "DUMMY_FIELD_PREFIX",
    "create_cloud",
    "create_cloud_xyz32",
    "dtype_from_fields",
    "read_points",
    "read_points_list",
    "read_points_numpy",
]
