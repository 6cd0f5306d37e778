"""rclpy.client."""

from rosl.node.client import Client

__all__ = ["Client"]
