"""rclpy.lifecycle.node."""

from rosl.node.lifecycle import LifecycleMixin, LifecycleNode, LifecycleNodeMixin
from rosl.node.managed import LifecycleState, TransitionCallbackReturn

__all__ = [
    "LifecycleMixin",
    "LifecycleNode",
    "LifecycleNodeMixin",
    "LifecycleState",
    "TransitionCallbackReturn",
]
