"""tf2_ros's ``BufferInterface``: ``transform`` and ``transform_full`` on top of lookups.

A subclass supplies ``lookup_transform``/``lookup_transform_full`` (and the ``can_``
variants); :class:`~rosl.tf2.buffer.Buffer` is the one rosl provides.
"""

from __future__ import annotations

from typing import Any

from rosl.tf2.errors import TransformException
from rosl.tf2.registration import TransformRegistration, convert


class NotImplementedException(TransformException):
    """A BufferInterface method its subclass did not provide."""

    def __init__(self) -> None:
        super().__init__("CanTransform or LookupTransform not implemented")
        self.errstr = "CanTransform or LookupTransform not implemented"


class BufferInterface:
    """Transform stamped data with whatever lookups a subclass provides."""

    def __init__(self) -> None:
        self.registration = TransformRegistration()

    def transform(
        self, object_stamped: Any, target_frame: str, timeout: Any = None, new_type: Any = None
    ) -> Any:
        """``object_stamped`` (a PointStamped, PoseStamped, ...) expressed in ``target_frame``.

        Raises:
            TransformException: the transform is not known within ``timeout``.
            TypeException: no do_transform function for the type.
        """
        do_transform = self.registration.get(type(object_stamped))
        header = object_stamped.header
        found = self.lookup_transform(target_frame, header.frame_id, header.stamp, timeout)
        result = do_transform(object_stamped, found)
        return result if new_type is None else convert(result, new_type)

    def transform_full(
        self, object_stamped: Any, target_frame: str, target_time: Any, fixed_frame: str,
        timeout: Any = None, new_type: Any = None,
    ) -> Any:  # fmt: skip
        """As :meth:`transform`, to ``target_time`` through ``fixed_frame`` held still."""
        do_transform = self.registration.get(type(object_stamped))
        header = object_stamped.header
        found = self.lookup_transform_full(
            target_frame, target_time, header.frame_id, header.stamp, fixed_frame, timeout
        )
        result = do_transform(object_stamped, found)
        return result if new_type is None else convert(result, new_type)

    def lookup_transform(self, *args: Any, **kwargs: Any) -> Any:
        """target←source at a time: provided by a subclass."""
        raise NotImplementedException

    def lookup_transform_full(self, *args: Any, **kwargs: Any) -> Any:
        """target←source between two times through a fixed frame: provided by a subclass."""
        raise NotImplementedException

    def can_transform(self, *args: Any, **kwargs: Any) -> Any:
        """Whether lookup_transform would succeed: provided by a subclass."""
        raise NotImplementedException

    def can_transform_full(self, *args: Any, **kwargs: Any) -> Any:
        """Whether lookup_transform_full would succeed: provided by a subclass."""
        raise NotImplementedException


def Stamped(obj: Any, stamp: Any, frame_id: str) -> Any:  # noqa: N802 - tf2_ros's name
    """Give ``obj`` a header with ``stamp`` and ``frame_id``."""
    from rosl.idl.registry import get_message_class

    obj.header = get_message_class("std_msgs/msg/Header")(frame_id=frame_id, stamp=stamp)
    return obj


__all__ = ["BufferInterface", "NotImplementedException", "Stamped"]
