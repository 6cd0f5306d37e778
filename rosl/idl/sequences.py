"""Numeric sequence fields that grow in place, as rclpy's ``array.array`` fields do.

rclpy holds a numeric ``T[]`` / ``T[<=N]`` field as an ``array.array``, so ROS 2 code writes
``feedback.sequence.append(x)``. rosl keeps numpy arrays (fast CDR, numpy maths); the array a
message holds is a :class:`SequenceArray` that remembers its message (weakly), and ``append``,
``extend``, ``insert`` and ``pop`` replace the message's field with the grown or shrunk array
(checked like any assignment: dtype, range, bound).
"""

from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, Any

import numpy as np

from rosl.idl.errors import FieldError

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable


class SequenceArray(np.ndarray):
    """A numpy array held by a message's sequence field; list-like growth changes that field."""

    _owner: tuple[weakref.ref[Any], str] | None = None

    def __array_finalize__(self, obj: Any) -> None:
        self._owner = None  # a slice or a result is not the message's field

    def _field(self) -> tuple[Any, str, np.ndarray]:
        target = None if self._owner is None else self._owner[0]()
        if target is None or self._owner is None:
            raise FieldError(
                "append/extend/insert/pop change a message's field (msg.field.append(x)); "
                "this array is a copy or a slice of one"
            )
        attr = self._owner[1]
        return target, attr, getattr(target, attr)

    def append(self, value: Any) -> None:
        """Add one value at the end of the message's field."""
        self.extend((value,))

    def extend(self, values: Iterable[Any]) -> None:
        """Add values at the end of the message's field."""
        target, attr, current = self._field()
        added = np.asarray(list(values))
        setattr(target, attr, np.concatenate([current.view(np.ndarray), added]) if added.size
                else current)  # fmt: skip

    def insert(self, index: int, value: Any) -> None:
        """Insert one value before ``index``."""
        target, attr, current = self._field()
        setattr(target, attr, np.insert(current.view(np.ndarray), index, value))

    def pop(self, index: int = -1) -> Any:
        """Remove the value at ``index`` (the last by default) and return it."""
        target, attr, current = self._field()
        value = current[index].item()
        setattr(target, attr, np.delete(current.view(np.ndarray), index))
        return value


def sequence_property(slot: str, attr: str, coerce: Callable[[Any], Any]) -> property:
    """A numeric sequence field: values are coerced, then held as a :class:`SequenceArray`."""

    def setter(self: Any, value: Any) -> None:
        array = coerce(value).view(SequenceArray)
        array._owner = (weakref.ref(self), attr)
        object.__setattr__(self, slot, array)

    def getter(self: Any) -> Any:
        return getattr(self, slot)

    return property(getter, setter)
