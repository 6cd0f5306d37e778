"""rclpy.service."""

from rosl.node.service import Service

__all__ = ["Service"]
