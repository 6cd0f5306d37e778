"""tf2_ros.buffer_interface."""

from rosl.tf2.errors import TypeException
from rosl.tf2.interface import BufferInterface, NotImplementedException, Stamped
from rosl.tf2.registration import ConvertRegistration, TransformRegistration, convert

__all__ = [
    "BufferInterface",
    "ConvertRegistration",
    "NotImplementedException",
    "Stamped",
    "TransformRegistration",
    "TypeException",
    "convert",
]
