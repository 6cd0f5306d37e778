"""rclpy.logging."""

from rosl.node.logging import LoggingSeverity, get_logger, set_logger_level

__all__ = ["LoggingSeverity", "get_logger", "set_logger_level"]
