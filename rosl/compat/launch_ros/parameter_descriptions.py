"""launch_ros.parameter_descriptions."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.ros_actions import ParameterFile, ParameterValue

__all__ = ["ParameterFile", "ParameterValue"]
__getattr__ = unsupported_names("launch_ros.parameter_descriptions", __all__)
