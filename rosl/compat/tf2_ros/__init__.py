"""``import tf2_ros`` under rosl: Buffer, listeners, broadcasters and tf2's exceptions.

Everything comes from ``rosl.tf2`` (no logic here); as tf2_ros re-exports tf2_py, so does
this. The submodules ``tf2_ros.buffer``, ``tf2_ros.transform_listener``... resolve as in
tf2_ros.
"""

from rosl.compat import tf2_py as _tf2_py
from rosl.compat.tf2_py import *  # noqa: F403 - BufferCore and the exceptions, as tf2_ros
from rosl.compat.unsupported import unsupported_names
from rosl.tf2.broadcaster import StaticTransformBroadcaster, TransformBroadcaster
from rosl.tf2.buffer import Buffer
from rosl.tf2.errors import TypeException
from rosl.tf2.interface import BufferInterface, NotImplementedException, Stamped
from rosl.tf2.listener import StaticTransformListener, TransformListener
from rosl.tf2.registration import ConvertRegistration, TransformRegistration, convert

__all__ = [
    *_tf2_py.__all__,
    "Buffer",
    "BufferInterface",
    "ConvertRegistration",
    "NotImplementedException",
    "Stamped",
    "StaticTransformBroadcaster",
    "StaticTransformListener",
    "TransformBroadcaster",
    "TransformListener",
    "TransformRegistration",
    "TypeException",
    "convert",
]
__getattr__ = unsupported_names("tf2_ros", __all__)
