"""The bus's numeric settings from the environment (``ROSL_*``), a bad value meaning the default.

Only bus/ reads these; each setting's meaning is documented where it is used.
"""

from __future__ import annotations

import os


def env_number(name: str, default: float) -> float:
    """The number in the environment variable ``name``; ``default`` if unset or not a number."""
    text = os.environ.get(name, "").strip()
    try:
        return float(text) if text else default
    except ValueError:
        return default
