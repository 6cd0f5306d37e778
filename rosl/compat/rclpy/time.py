"""rclpy.time."""

from rosl.node.clock import Duration, Time

__all__ = ["Duration", "Time"]
