"""rclpy.context."""

from rosl.node.context import Context

__all__ = ["Context"]
