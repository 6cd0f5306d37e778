"""rclpy.exceptions."""

from rosl.node.errors import (
    InvalidNameError as InvalidTopicNameException,
)
from rosl.node.errors import (
    InvalidParameterTypeException,
    InvalidParameterValueException,
    ParameterAlreadyDeclaredException,
    ParameterNotDeclaredException,
)
from rosl.node.errors import (
    NotInitializedError as NotInitializedException,
)

__all__ = [
    "InvalidParameterTypeException",
    "InvalidParameterValueException",
    "InvalidTopicNameException",
    "NotInitializedException",
    "ParameterAlreadyDeclaredException",
    "ParameterNotDeclaredException",
]
