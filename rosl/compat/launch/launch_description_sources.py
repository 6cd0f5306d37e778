"""launch.launch_description_sources."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.actions import (
    AnyLaunchDescriptionSource,
    FrontendLaunchDescriptionSource,
    PythonLaunchDescriptionSource,
    YAMLLaunchDescriptionSource,
)

__all__ = [
    "AnyLaunchDescriptionSource",
    "FrontendLaunchDescriptionSource",
    "PythonLaunchDescriptionSource",
    "YAMLLaunchDescriptionSource",
]
__getattr__ = unsupported_names("launch.launch_description_sources", __all__)
