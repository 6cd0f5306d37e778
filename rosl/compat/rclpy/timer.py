"""rclpy.timer."""

from rosl.node.timer import Rate, Timer

__all__ = ["Rate", "Timer"]
