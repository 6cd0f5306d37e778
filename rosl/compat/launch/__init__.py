"""``import launch`` under rosl (the launch API rosl implements; no logic here).

Submodules (``launch.actions``, ``launch.substitutions``, ...) are reachable after
``import launch``, as with launch, and imported on first use.
"""

import importlib
from typing import Any

from rosl.compat.unsupported import unsupported_names
from rosl.launch.context import LaunchContext
from rosl.launch.description import Action, Condition, LaunchDescription
from rosl.launch.event_handlers import EventHandler
from rosl.launch.service import LaunchService
from rosl.launch.substitutions import SomeSubstitutions as SomeSubstitutionsType
from rosl.launch.substitutions import Substitution

__all__ = [
    "Action",
    "Condition",
    "EventHandler",
    "LaunchContext",
    "LaunchDescription",
    "LaunchService",
    "SomeSubstitutionsType",
    "Substitution",
]

_SUBMODULES = frozenset(
    ("action", "actions", "condition", "conditions", "event_handler", "event_handlers", "events",
     "launch_context", "launch_description", "launch_description_sources", "logging",
     "some_substitutions_type", "substitution", "substitutions", "utilities")
)  # fmt: skip
_unsupported = unsupported_names("launch", [*__all__, *sorted(_SUBMODULES)])


def __getattr__(name: str) -> Any:
    if name in _SUBMODULES:
        return importlib.import_module(f"launch.{name}")
    return _unsupported(name)
