"""Import shims so ROS 2 Python code runs under rosl unchanged.

``install()`` adds one meta-path finder that serves ``<pkg>.msg`` / ``<pkg>.srv`` modules for
interface packages on rosl's search path — only where no real module of that name exists.
The shims hold no logic of their own; they delegate to ``rosl.idl``. Nothing here imports
numpy until a message class is actually requested.
"""

from __future__ import annotations

from rosl.compat.interfaces import install

__all__ = ["install"]
