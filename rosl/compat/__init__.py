"""Import shims so ROS 2 Python code runs under rosl unchanged.

* ``<pkg>.msg`` / ``<pkg>.srv`` for every interface package on rosl's search path
  (``interfaces.py``), only where no real module of that name exists;
* ``rclpy`` (and, while a launch file loads, ``launch`` / ``launch_ros``) backed by rosl
  (``aliases.py``); a real installed rclpy wins unless rosl started the process.

The shims hold no logic of their own; they delegate to the rest of rosl.
"""

from __future__ import annotations

from rosl.compat import aliases, interfaces


def install(*, force: bool = False) -> None:
    """Install the import hooks (idempotent); ``force`` prefers rosl's rclpy to a real one."""
    interfaces.install()
    aliases.install(force=force)


__all__ = ["install"]
