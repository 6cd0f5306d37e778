"""rclpy.clock."""

from rosl.node.clock import Clock, ClockType, ROSClock

__all__ = ["Clock", "ClockType", "ROSClock"]
