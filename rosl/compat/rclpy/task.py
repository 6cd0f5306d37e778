"""rclpy.task."""

from rosl.executor import Future

__all__ = ["Future"]
