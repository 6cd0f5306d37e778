"""launch_ros.events: lifecycle events need lifecycle nodes, which rosl has not."""

import importlib
from typing import Any

from rosl.compat.unsupported import unsupported_names

__all__: list[str] = []
_unsupported = unsupported_names("launch_ros.events", __all__)


def __getattr__(name: str) -> Any:
    if name == "lifecycle":
        return importlib.import_module("launch_ros.events.lifecycle")
    return _unsupported(name)
