"""``import launch_ros`` under rosl (no logic here).

Submodules (``launch_ros.actions``, ``launch_ros.substitutions``, ...) are reachable after
``import launch_ros``, as with launch_ros, and imported on first use.
"""

import importlib
from typing import Any

from rosl.compat.unsupported import unsupported_names

__all__: list[str] = []

_SUBMODULES = frozenset(
    ("actions", "descriptions", "event_handlers", "events", "parameter_descriptions",
     "substitutions")
)  # fmt: skip
_unsupported = unsupported_names("launch_ros", sorted(_SUBMODULES))


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"launch_ros.{name}")
    return _unsupported(name)
