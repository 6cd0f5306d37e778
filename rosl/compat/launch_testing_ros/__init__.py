"""``import launch_testing_ros`` under rosl (rosl.launch.testing.ros implements it; no logic)."""

import importlib
from typing import Any

from rosl.compat.unsupported import unsupported_names
from rosl.launch.testing.ros import WaitForTopics

__all__ = ["WaitForTopics", "actions", "tools"]
_unsupported = unsupported_names("launch_testing_ros", __all__)


def __getattr__(name: str) -> Any:
    if name in ("actions", "tools"):
        return importlib.import_module(f"launch_testing_ros.{name}")
    return _unsupported(name)
