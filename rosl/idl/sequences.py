"""Numeric sequence fields that grow in place, as rclpy's ``array.array`` fields do.

rclpy holds a numeric ``T[]`` / ``T[<=N]`` field as an ``array.array``, so ROS 2 code writes
``feedback.sequence.append(x)``. rosl keeps numpy arrays (fast CDR, numpy maths); the array a
message holds is a :class:`SequenceArray` that remembers its message (weakly), and ``append``,
``extend``, ``insert`` and ``pop`` replace the message's field with the grown or shrunk array
(checked like any assignment: dtype, range, bound). Iterating or indexing it gives Python
numbers, and it prints as ``array('i', [0, 1])``, as rclpy's fields do.

A sequence left empty at construction holds nothing until it is first read (then an empty
array is made): a message whose numeric sequences stay empty (a node's ``ParameterEvent``)
never loads numpy. The serializer reads such a field as :data:`EMPTY` (see ``wire_view``).
"""

from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Callable


_ARRAY_TYPES: tuple[type, ...] = ()


def array_types() -> tuple[type, ...]:
    """``(numpy.ndarray, SequenceArray)``: the arrays a field takes as they are (imports numpy)."""
    global _ARRAY_TYPES  # filled once, on first use
    if not _ARRAY_TYPES:
        import numpy as np

        from rosl.idl.sequence_array import SequenceArray

        _ARRAY_TYPES = (np.ndarray, SequenceArray)
    return _ARRAY_TYPES


class _EmptySequence:
    """An empty numeric sequence as rosbags' generated serializer reads it (no numpy needed)."""

    __slots__ = ()

    def __len__(self) -> int:
        return 0

    def view(self, _dtype: object) -> bytes:
        return b""

    def byteswap(self) -> _EmptySequence:
        return self


EMPTY = _EmptySequence()


def sequence_property(slot: str, attr: str, coerce: Callable[[Any], Any]) -> property:
    """A numeric sequence field: values are coerced, then held as a :class:`SequenceArray`.

    ``None`` (the default) leaves the slot holding None: empty, with no array made yet.
    """

    def setter(self: Any, value: Any) -> None:
        if value is None:
            object.__setattr__(self, slot, None)
            return
        array = coerce(value).view(_ARRAY_TYPES[1] if _ARRAY_TYPES else array_types()[1])
        array._owner = (weakref.ref(self), attr)
        object.__setattr__(self, slot, array)

    def getter(self: Any) -> Any:
        array = getattr(self, slot)
        if array is None:  # empty since construction: its array is made now
            array = coerce(None).view(_ARRAY_TYPES[1] if _ARRAY_TYPES else array_types()[1])
            array._owner = (weakref.ref(self), attr)
            object.__setattr__(self, slot, array)
            return array
        owner = array._owner
        if owner is None or owner[0]() is not self:  # a copied message: its own view
            array = array.view(_ARRAY_TYPES[1])  # set before: numpy and the class are loaded
            array._owner = (weakref.ref(self), attr)
            object.__setattr__(self, slot, array)
        return array

    return property(getter, setter)
