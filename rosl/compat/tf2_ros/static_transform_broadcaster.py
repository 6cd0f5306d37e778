"""tf2_ros.static_transform_broadcaster."""

from rosl.tf2.broadcaster import StaticTransformBroadcaster

__all__ = ["StaticTransformBroadcaster"]
