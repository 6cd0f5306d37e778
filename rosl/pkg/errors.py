"""Errors about packages and their executables."""

from __future__ import annotations

from rosl.errors import RoslError


class PackageError(RoslError):
    """A package or executable that cannot be found or used."""


class ExecutableError(PackageError):
    """An executable whose declaration points at no module or function (``file:line: ...``)."""
