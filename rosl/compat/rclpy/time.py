"""rclpy.time."""

from rosl.node.clock import Time

__all__ = ["Time"]
