"""``import rclpy`` under rosl: the names rclpy code uses, backed by rosl (no logic here)."""

from rosl import (
    create_node,
    get_default_context,
    get_global_executor,
    init,
    ok,
    shutdown,
    spin,
    spin_once,
    spin_until_future_complete,
    try_shutdown,
)

__all__ = [
    "create_node",
    "get_default_context",
    "get_global_executor",
    "init",
    "ok",
    "shutdown",
    "spin",
    "spin_once",
    "spin_until_future_complete",
    "try_shutdown",
]
