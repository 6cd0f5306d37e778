"""rclpy.task."""

from rosl.node.task import Future, Task

__all__ = ["Future", "Task"]
