"""``import launch`` under rosl (the launch API rosl implements; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.context import LaunchContext
from rosl.launch.description import LaunchDescription

__all__ = ["LaunchContext", "LaunchDescription"]
__getattr__ = unsupported_names("launch", __all__)
