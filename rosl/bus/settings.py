"""The bus's numeric settings from the environment (``ROSL_*``), a bad value meaning the default.

Only bus/ reads these; each setting's meaning is documented where it is used.
"""

from __future__ import annotations

import math
import os


def env_number(name: str, default: float) -> float:
    """The number in the environment variable ``name``; ``default`` if unset or not a number.

    ``inf`` and ``nan`` are not numbers here (every setting is converted to whole units).
    """
    text = os.environ.get(name, "").strip()
    try:
        value = float(text) if text else default
    except ValueError:
        return default
    return value if math.isfinite(value) else default
