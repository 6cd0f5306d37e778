"""tf2_geometry_msgs.tf2_geometry_msgs (the module tf2_geometry_msgs re-exports)."""

from rosl.tf2 import geometry as _geometry
from rosl.tf2.geometry import *  # noqa: F403 - the functions tf2_geometry_msgs offers

__all__ = _geometry.__all__
