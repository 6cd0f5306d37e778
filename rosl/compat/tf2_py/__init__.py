"""``import tf2_py`` under rosl: BufferCore and tf2's exceptions, from ``rosl.tf2``."""

from rosl.tf2.core import BufferCore
from rosl.tf2.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)

__all__ = [
    "BufferCore",
    "ConnectivityException",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "TimeoutException",
    "TransformException",
]
