"""tf2_ros.static_transform_listener."""

from rosl.tf2.listener import StaticTransformListener

__all__ = ["StaticTransformListener"]
