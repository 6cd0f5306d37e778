"""launch_ros.substitutions."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.substitutions import FindPackagePrefix, FindPackageShare

__all__ = ["FindPackagePrefix", "FindPackageShare"]
__getattr__ = unsupported_names("launch_ros.substitutions", __all__)
