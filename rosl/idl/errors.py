"""Errors of the interface layer: bad .msg/.srv files, unknown types, bad message values."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from rosl.errors import RoslError

if TYPE_CHECKING:
    import os


def display_path(path: str | os.PathLike[str]) -> str:
    """Return ``path`` relative to the current directory when it lies below it."""
    p = Path(path)
    try:
        return str(p.resolve().relative_to(Path.cwd().resolve()))
    except (ValueError, OSError):
        return str(p)


class InterfaceError(RoslError):
    """A problem with an interface definition or type name, optionally located in a file.

    Renders as ``path:line:col: message`` when a location is known, else as ``message``.
    """

    def __init__(
        self,
        message: str,
        path: str | os.PathLike[str] | None = None,
        line: int = 0,
        col: int = 0,
    ) -> None:
        self.message = message
        self.path = Path(path) if path is not None else None
        self.line = line
        self.col = col
        super().__init__(self.render())

    def render(self) -> str:
        """Return the one-line text of this error."""
        if self.path is None:
            return self.message
        where = display_path(self.path)
        if self.line:
            where += f":{self.line}"
            if self.col:
                where += f":{self.col}"
        return f"{where}: {self.message}"


class FieldError(InterfaceError, TypeError):
    """A message field that does not exist, or a value a field cannot hold."""


class PointCloudError(InterfaceError, ValueError, AssertionError):
    """A PointCloud2 whose fields, sizes or points do not fit together.

    Also an ``AssertionError``: sensor_msgs_py asserts these, and code may catch that.
    """


class NotAMessageError(InterfaceError, TypeError):
    """Something used as a message (type) that is not one: a service, or a plain object."""
