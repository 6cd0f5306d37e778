"""launch_testing_ros.actions (rosl.launch.testing.isolation implements it; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.testing.isolation import EnableRmwIsolation

__all__ = ["EnableRmwIsolation"]
__getattr__ = unsupported_names("launch_testing_ros.actions", __all__)
