"""launch_yaml.launch_description_sources."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.actions import YAMLLaunchDescriptionSource

__all__ = ["YAMLLaunchDescriptionSource"]
__getattr__ = unsupported_names("launch_yaml.launch_description_sources", __all__)
