"""rclpy.guard_condition."""

from rosl.node.guard_condition import GuardCondition

__all__ = ["GuardCondition"]
