"""Errors of the node layer (with rclpy's exception names as aliases where rclpy has them)."""

from __future__ import annotations

from rosl.errors import RoslError


class NodeError(RoslError):
    """A node-level problem: names, arguments, QoS, services, shutdown state."""


class InvalidNameError(NodeError, ValueError):
    """A node, namespace, topic or service name that ROS 2's rules reject."""


class RosArgsError(NodeError):
    """A malformed ``--ros-args`` section."""


class ParameterError(NodeError):
    """Base of parameter errors."""


class ParameterNotDeclaredException(ParameterError, KeyError):  # noqa: N818 - rclpy's name
    """Raised when getting or setting a parameter that was never declared."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else "parameter not declared"


class ParameterAlreadyDeclaredException(ParameterError):  # noqa: N818 - rclpy's name
    """Raised when declaring a parameter twice."""


class InvalidParameterValueException(ParameterError, ValueError):  # noqa: N818 - rclpy's name
    """Raised when a value is rejected (by type, range, read-only or a callback)."""


class InvalidParameterTypeException(InvalidParameterValueException):
    """Raised when a value's type differs from the parameter's declared type."""


class TimerPeriodError(NodeError, ValueError):
    """A timer period that is not a finite number of seconds > 0 (or past int64 nanoseconds)."""


class ThreadCountError(NodeError, ValueError):
    """An executor was given fewer than one thread."""


class NotInitializedError(NodeError):
    """rosl.init() was not called (or the context is shut down)."""


class LifecycleTransitionError(NodeError, RuntimeError):
    """A lifecycle transition that does not start in the node's current state."""
