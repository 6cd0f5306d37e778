"""rclpy.waitable."""

from rosl.node.waitable import NumberOfEntities, Waitable

__all__ = ["NumberOfEntities", "Waitable"]
