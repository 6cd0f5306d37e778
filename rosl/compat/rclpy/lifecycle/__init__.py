"""rclpy.lifecycle: managed nodes, backed by rosl (no logic here).

As in rclpy, ``Node``, ``State`` and ``Publisher`` are aliases of LifecycleNode, LifecycleState
and LifecyclePublisher (left out of ``__all__``).
"""

from rosl.node.lifecycle import LifecycleMixin, LifecycleNode, LifecycleNodeMixin
from rosl.node.managed import (
    LifecyclePublisher,
    LifecycleState,
    ManagedEntity,
    SimpleManagedEntity,
    TransitionCallbackReturn,
)

Node = LifecycleNode
State = LifecycleState
Publisher = LifecyclePublisher

__all__ = [
    "LifecycleMixin",
    "LifecycleNode",
    "LifecycleNodeMixin",
    "LifecyclePublisher",
    "LifecycleState",
    "ManagedEntity",
    "SimpleManagedEntity",
    "TransitionCallbackReturn",
]
