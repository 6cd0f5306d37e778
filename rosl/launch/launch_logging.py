"""launch.logging: ``get_logger(name)``, a Python logger printing as the launcher does.

A launch file's ``launch.logging.get_logger('my_launch').info('x')`` prints
``[INFO] [my_launch]: x`` on the launcher's output, beside its own lines.
"""

from __future__ import annotations

import logging
import sys

_ROOT = "rosl.launch.user"
_LEVELS = {"WARNING": "WARN"}  # as launch's screen format shows them


class _ScreenFormatter(logging.Formatter):
    def format(self, record: logging.LogRecord) -> str:
        name = record.name.removeprefix(f"{_ROOT}.") if record.name != _ROOT else "launch"
        level = _LEVELS.get(record.levelname, record.levelname)
        return f"[{level}] [{name}]: {record.getMessage()}"


def _root() -> logging.Logger:
    root = logging.getLogger(_ROOT)
    if not root.handlers:
        handler = logging.StreamHandler(sys.stdout)
        handler.setFormatter(_ScreenFormatter())
        root.addHandler(handler)
        root.setLevel(logging.INFO)
        root.propagate = False
    return root


def get_logger(name: str | None = None) -> logging.Logger:
    """The logger ``name`` (``launch`` without one), printing ``[LEVEL] [name]: message``."""
    root = _root()
    return root if name is None else root.getChild(name)


def reset() -> None:
    """Forget the handlers (launch.logging.reset)."""
    root = logging.getLogger(_ROOT)
    for handler in list(root.handlers):
        root.removeHandler(handler)


__all__ = ["get_logger", "reset"]
