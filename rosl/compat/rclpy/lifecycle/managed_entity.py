"""rclpy.lifecycle.managed_entity."""

from rosl.node.managed import ManagedEntity, SimpleManagedEntity, TransitionCallbackReturn

__all__ = ["ManagedEntity", "SimpleManagedEntity", "TransitionCallbackReturn"]
