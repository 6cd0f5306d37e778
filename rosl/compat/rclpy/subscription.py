"""rclpy.subscription."""

from rosl.node.subscription import Subscription

__all__ = ["Subscription"]
