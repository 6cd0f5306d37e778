"""launch_ros.actions."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.ros_actions import Node, PushRosNamespace, SetParameter, SetRemap

__all__ = ["Node", "PushRosNamespace", "SetParameter", "SetRemap"]
__getattr__ = unsupported_names("launch_ros.actions", __all__)
