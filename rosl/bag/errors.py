"""Errors about recordings."""

from __future__ import annotations

from rosl.errors import RoslError


class BagError(RoslError):
    """A recording that cannot be written or read (names the folder or file)."""
