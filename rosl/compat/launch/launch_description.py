"""launch.launch_description: ``LaunchDescription`` (for type hints; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.description import LaunchDescription

__all__ = ["LaunchDescription"]
__getattr__ = unsupported_names("launch.launch_description", __all__)
