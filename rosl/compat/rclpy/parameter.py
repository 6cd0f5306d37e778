"""rclpy.parameter."""

from rosl.node.parameter_values import (
    PARAMETER_SEPARATOR_STRING,
    get_parameter_value,
    parameter_dict_from_yaml_file,
    parameter_value_to_python,
)
from rosl.node.parameters import Parameter, ParameterType

__all__ = [
    "PARAMETER_SEPARATOR_STRING",
    "Parameter",
    "ParameterType",
    "get_parameter_value",
    "parameter_dict_from_yaml_file",
    "parameter_value_to_python",
]
