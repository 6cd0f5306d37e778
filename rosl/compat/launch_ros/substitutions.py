"""launch_ros.substitutions."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.substitutions import (
    ExecutableInPackage,
    FindPackage,
    FindPackagePrefix,
    FindPackageShare,
)

__all__ = ["ExecutableInPackage", "FindPackage", "FindPackagePrefix", "FindPackageShare"]
__getattr__ = unsupported_names("launch_ros.substitutions", __all__)
