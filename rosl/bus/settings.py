"""The bus's numeric settings from the environment (``ROSL_*``).

Only bus/ reads these; each setting's meaning is documented where it is used. A value that is
not a number, or below the setting's least, is a user mistake: one line naming it, not a
silent default.
"""

from __future__ import annotations

import math
import os

from rosl.bus.errors import BusError


def env_number(name: str, default: float, unit: str, least: float = 0.0) -> float:
    """The number in the environment variable ``name``; ``default`` if unset or blank.

    ``inf`` and ``nan`` are not numbers here (every setting is converted to whole units).

    Raises:
        BusError: the value is not a finite number of at least ``least``.
    """
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value < least:
        raise BusError(
            f"{name}={text!r} is not a number of {unit} from {least:g} (unset: {default:g})"
        )
    return value
