"""``import rclpy`` under rosl: the names rclpy code uses, backed by rosl (no logic here).

Submodules (``rclpy.executors``, ``rclpy.qos``...) are reachable after ``import rclpy``, as
with rclpy, and imported on first use.
"""

import importlib
from typing import Any

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


_SUBMODULES = frozenset(
    ("action", "callback_groups", "client", "clock", "context", "duration", "exceptions",
     "executors", "guard_condition", "logging", "node", "parameter", "publisher", "qos", "service",
     "signals", "subscription", "task", "time", "timer", "utilities", "waitable")
)  # fmt: skip


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"rclpy.{name}")
    raise AttributeError(f"module 'rclpy' has no attribute '{name}'")
