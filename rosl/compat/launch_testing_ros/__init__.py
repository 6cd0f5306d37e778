"""``import launch_testing_ros`` under rosl (rosl.launch.testing.ros implements it; no logic)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.testing.ros import WaitForTopics

__all__ = ["WaitForTopics"]
__getattr__ = unsupported_names("launch_testing_ros", __all__)
