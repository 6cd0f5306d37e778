"""rclpy.exceptions."""

from rosl.node.errors import (
    InvalidParameterTypeException,
    InvalidParameterValueException,
    ParameterAlreadyDeclaredException,
    ParameterNotDeclaredException,
)
from rosl.node.errors import (
    NotInitializedError as NotInitializedException,
)
from rosl.node.names import InvalidNameError as InvalidTopicNameException

__all__ = [
    "InvalidParameterTypeException",
    "InvalidParameterValueException",
    "InvalidTopicNameException",
    "NotInitializedException",
    "ParameterAlreadyDeclaredException",
    "ParameterNotDeclaredException",
]
