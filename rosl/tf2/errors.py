"""tf2's exceptions (tf2_py / tf2_ros names), rooted in :class:`rosl.errors.RoslError`.

Being ``RoslError`` s, one that ends an executable is reported as one line::

    TransformException
    ├── LookupException            a frame that does not exist, or a loop in the tree
    ├── ConnectivityException      two frames in separate trees
    ├── ExtrapolationException     a time outside the data kept for an edge
    ├── InvalidArgumentException   an empty frame id, or one starting with '/'
    └── TimeoutException           a wait that ended before the transform came
"""

from __future__ import annotations

from rosl.errors import RoslError


class TransformException(RoslError):  # noqa: N818 - tf2's name
    """A transform could not be computed (tf2.TransformException)."""


class LookupException(TransformException):
    """A frame is unknown (tf2.LookupException)."""


class ConnectivityException(TransformException):
    """The frames are not part of one tree (tf2.ConnectivityException)."""


class ExtrapolationException(TransformException):
    """The time asked for is outside the data kept (tf2.ExtrapolationException)."""


class InvalidArgumentException(TransformException):
    """A frame id that tf2 refuses (tf2.InvalidArgumentException)."""


class TimeoutException(TransformException):
    """A wait for a transform ran out (tf2.TimeoutException)."""


class TypeException(TransformException):
    """No registered conversion for a type (tf2_ros.TypeException)."""

    def __init__(self, errstr: str) -> None:
        super().__init__(errstr)
        self.errstr = errstr


class Tf2ArgumentError(RoslError):
    """A tf2 program (static_transform_publisher, tf2_echo...) got arguments it cannot use."""


__all__ = [
    "ConnectivityException",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "Tf2ArgumentError",
    "TimeoutException",
    "TransformException",
    "TypeException",
]
