"""Errors of the transport layer."""

from __future__ import annotations

from rosl.errors import RoslError


class BusError(RoslError):
    """The bus cannot be used: sockets, multicast setup, or a bad domain/interface."""
