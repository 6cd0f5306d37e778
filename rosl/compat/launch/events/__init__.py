"""launch.events: ``Shutdown``, ``IncludeLaunchDescription`` and ``matches_action``."""

import importlib
from typing import Any

from rosl.compat.unsupported import unsupported_names
from rosl.launch.actions import Shutdown
from rosl.launch.events import IncludeLaunchDescription, matches_action

__all__ = ["IncludeLaunchDescription", "Shutdown", "matches_action"]
_unsupported = unsupported_names("launch.events", __all__)


def __getattr__(name: str) -> Any:
    if name == "process":
        return importlib.import_module("launch.events.process")
    return _unsupported(name)
