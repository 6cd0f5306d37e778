"""launch.events: ``Shutdown`` (the event EmitEvent takes)."""

import importlib
from typing import Any

from rosl.compat.unsupported import unsupported_names
from rosl.launch.actions import Shutdown

__all__ = ["Shutdown"]
_unsupported = unsupported_names("launch.events", __all__)


def __getattr__(name: str) -> Any:
    if name == "process":
        return importlib.import_module("launch.events.process")
    return _unsupported(name)
