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
    (
        "action",
        "callback_groups",
        "client",
        "clock",
        "context",
        "duration",
        "event_handler",
        "exceptions",
        "executors",
        "guard_condition",
        "lifecycle",
        "logging",
        "node",
        "parameter",
        "parameter_client",
        "publisher",
        "qos",
        "qos_event",
        "qos_overriding_options",
        "serialization",
        "service",
        "signals",
        "subscription",
        "task",
        "time",
        "timer",
        "utilities",
        "waitable",
    )
)


def __getattr__(name: str) -> Any:
    if name in ("Context", "Parameter"):  # rclpy has them at the top too (tests use them)
        return getattr(importlib.import_module(f"rclpy.{name.lower()}"), name)
    if name in _SUBMODULES:
        return importlib.import_module(f"rclpy.{name}")
    raise AttributeError(f"module 'rclpy' has no attribute '{name}'")
