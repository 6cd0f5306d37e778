"""launch.conditions."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.actions import LaunchConfigurationEquals, LaunchConfigurationNotEquals
from rosl.launch.description import IfCondition, UnlessCondition

__all__ = [
    "IfCondition",
    "LaunchConfigurationEquals",
    "LaunchConfigurationNotEquals",
    "UnlessCondition",
]
__getattr__ = unsupported_names("launch.conditions", __all__)
