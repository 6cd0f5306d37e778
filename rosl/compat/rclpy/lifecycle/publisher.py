"""rclpy.lifecycle.publisher."""

from rosl.node.managed import LifecyclePublisher

__all__ = ["LifecyclePublisher"]
