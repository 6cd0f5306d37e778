"""launch.launch_description_sources."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.actions import (
    AnyLaunchDescriptionSource,
    FrontendLaunchDescriptionSource,
    PythonLaunchDescriptionSource,
    YAMLLaunchDescriptionSource,
)
from rosl.launch.loader import description_from_file

get_launch_description_from_any_launch_file = description_from_file
get_launch_description_from_python_launch_file = description_from_file
get_launch_description_from_frontend_launch_file = description_from_file

__all__ = [
    "AnyLaunchDescriptionSource",
    "FrontendLaunchDescriptionSource",
    "PythonLaunchDescriptionSource",
    "YAMLLaunchDescriptionSource",
    "get_launch_description_from_any_launch_file",
    "get_launch_description_from_frontend_launch_file",
    "get_launch_description_from_python_launch_file",
]
__getattr__ = unsupported_names("launch.launch_description_sources", __all__)
