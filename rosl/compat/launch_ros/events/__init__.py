"""launch_ros.events: the lifecycle events (``launch_ros.events.lifecycle``)."""

import importlib
from typing import Any

from rosl.compat.unsupported import unsupported_names
from rosl.launch.lifecycle_events import matches_node_name

__all__ = ["matches_node_name"]
_unsupported = unsupported_names("launch_ros.events", __all__)


def __getattr__(name: str) -> Any:
    if name == "lifecycle":
        return importlib.import_module("launch_ros.events.lifecycle")
    return _unsupported(name)
