"""launch_xml.launch_description_sources."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.actions import XMLLaunchDescriptionSource

__all__ = ["XMLLaunchDescriptionSource"]
__getattr__ = unsupported_names("launch_xml.launch_description_sources", __all__)
