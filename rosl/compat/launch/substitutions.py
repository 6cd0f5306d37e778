"""launch.substitutions."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.substitutions import (
    EnvironmentVariable,
    LaunchConfiguration,
    PathJoinSubstitution,
    PythonExpression,
    TextSubstitution,
)

__all__ = [
    "EnvironmentVariable",
    "LaunchConfiguration",
    "PathJoinSubstitution",
    "PythonExpression",
    "TextSubstitution",
]
__getattr__ = unsupported_names("launch.substitutions", __all__)
