"""rclpy.utilities."""

from rosl import get_default_context, ok, try_shutdown
from rosl.node.ros_args import remove_ros_args

__all__ = ["get_default_context", "ok", "remove_ros_args", "try_shutdown"]
