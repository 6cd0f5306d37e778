"""rclpy.parameter."""

from rosl.node.parameters import (
    PARAMETER_SEPARATOR_STRING,
    Parameter,
    ParameterType,
    get_parameter_value,
    parameter_value_to_python,
)

__all__ = [
    "PARAMETER_SEPARATOR_STRING",
    "Parameter",
    "ParameterType",
    "get_parameter_value",
    "parameter_value_to_python",
]
