"""The numpy array a message's numeric sequence field holds (see :mod:`rosl.idl.sequences`).

Its own module so that numpy is imported with the first such array, not with every message
class (a process that never touches a numeric array never loads numpy).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from rosl.idl.errors import FieldError

if TYPE_CHECKING:
    import weakref
    from collections.abc import Iterable


# numpy's type characters -> array.array's typecodes (what rclpy prints)
_TYPECODES = {"b": "b", "B": "B", "h": "h", "H": "H", "i": "i", "I": "I", "l": "q", "L": "Q",
              "q": "q", "Q": "Q", "f": "f", "d": "d", "?": "?"}  # fmt: skip


class SequenceArray(np.ndarray):
    """A numpy array held by a message's sequence field; list-like growth changes that field."""

    _owner: tuple[weakref.ref[Any], str] | None = None

    def __array_finalize__(self, obj: Any) -> None:
        self._owner = None  # a slice or a result is not the message's field

    def __array_wrap__(self, array: Any, context: Any = None, return_scalar: bool = False) -> Any:
        result = array.view(np.ndarray)  # maths on a field gives plain arrays and numbers
        return result[()] if return_scalar or result.ndim == 0 else result

    def __iter__(self) -> Any:
        return iter(self.tolist())  # Python numbers, as array.array yields

    def __getitem__(self, key: Any) -> Any:
        item = super().__getitem__(key)
        return item.item() if isinstance(item, np.generic) else item

    def __repr__(self) -> str:
        if self.ndim != 1:
            return super().__repr__()
        return f"array('{_TYPECODES.get(self.dtype.char, self.dtype.char)}', {self.tolist()})"

    __str__ = __repr__

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
        value = current[index]  # a Python number (see __getitem__)
        setattr(target, attr, np.delete(current.view(np.ndarray), index))
        return value
