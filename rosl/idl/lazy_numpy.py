"""numpy, imported on first use: a process that never touches a numeric array never loads it.

``np`` stands in for the module (each attribute is fetched once, then held like a module's own);
``is_numpy`` tests a value against a numpy type without importing numpy for plain values — a
value cannot be a numpy object while numpy is not loaded.
"""

from __future__ import annotations

import importlib
import sys
from types import ModuleType
from typing import Any


class _LazyNumpy(ModuleType):
    """The numpy module, imported at its first attribute access."""

    def __getattr__(self, name: str) -> Any:
        value = getattr(importlib.import_module("numpy"), name)
        setattr(self, name, value)
        return value


np: Any = _LazyNumpy("numpy")


def is_numpy(value: object, kind: str) -> bool:
    """Whether ``value`` is an instance of ``numpy.<kind>`` (False while numpy is not loaded)."""
    return "numpy" in sys.modules and isinstance(value, getattr(np, kind))
