"""rclpy.publisher."""

from rosl.node.publisher import Publisher

__all__ = ["Publisher"]
