"""Errors of world and robot files."""

from __future__ import annotations

from rosl.errors import RoslError


class WorldFileError(RoslError):
    """A world or robot file that cannot be used; names file:line and what is expected."""


class SimError(RoslError):
    """Simulator options that cannot run (named, with what they need)."""
