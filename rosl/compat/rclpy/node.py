"""rclpy.node."""

from rosl.node.node import Node

__all__ = ["Node"]
