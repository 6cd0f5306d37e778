"""rclpy.duration."""

from rosl.node.clock import Duration

__all__ = ["Duration"]
