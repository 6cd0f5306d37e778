"""tf2_ros.transform_broadcaster."""

from rosl.tf2.broadcaster import TransformBroadcaster

__all__ = ["TransformBroadcaster"]
