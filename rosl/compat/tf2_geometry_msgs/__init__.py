"""``import tf2_geometry_msgs`` under rosl: the do_transform_* functions of ``rosl.tf2``."""

from rosl.tf2 import geometry as _geometry
from rosl.tf2.geometry import *  # noqa: F403 - the functions tf2_geometry_msgs offers

__all__ = _geometry.__all__
