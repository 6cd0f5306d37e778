"""launch_ros.descriptions."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.ros_actions import ComposableNode, ParameterFile, ParameterValue

__all__ = ["ComposableNode", "ParameterFile", "ParameterValue"]
__getattr__ = unsupported_names("launch_ros.descriptions", __all__)
