"""Errors of launch files and launched processes."""

from __future__ import annotations

from rosl.errors import RoslError


class LaunchError(RoslError):
    """A launch file that cannot be loaded or run (names the file and line when known)."""
