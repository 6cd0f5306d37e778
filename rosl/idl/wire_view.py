"""Messages as rosbags' generated CDR serializer reads them.

rosbags holds ``byte`` as a signed int8 and a byte array as an int8 numpy array, where rosl
holds rclpy's ``bytes`` of length 1; and a numeric sequence left empty since construction
holds no array at all (see ``sequences.py``). :func:`wire_view` gives the serializer a view
with the values it expects; messages with neither anywhere inside are returned as they are.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

from rosl.idl.messages import to_byte
from rosl.idl.sequences import EMPTY

if TYPE_CHECKING:
    import numpy as np

    from rosl.idl.base import Message
else:
    from rosl.idl.lazy_numpy import np


def wire_view(message: Message) -> Any:
    """Return ``message`` as rosbags' CDR serializer reads it.

    Raises:
        FieldError: a byte field holds something that is not a byte (named by its path).
    """
    if not getattr(message, "_has_bytes", False) and not _has_empty(message):
        return message
    view = SimpleNamespace()
    lazy = message._lazy_sequences  # type: ignore[attr-defined]
    for field, attr, ftype in zip(
        message._spec.fields, message._fields, message._field_types, strict=True
    ):
        if "_" + attr in lazy and getattr(message, "_" + attr) is None:
            setattr(view, field.name, EMPTY)
            continue
        value = getattr(message, attr)
        if ftype.base == "byte":
            where = f"{message.__msgtype__}.{attr}"
            if not ftype.is_array:
                value = int.from_bytes(to_byte(value, where), "little", signed=True)
            else:
                value = _byte_array(value, where)
        elif not ftype.is_primitive:
            value = [wire_view(v) for v in value] if ftype.is_array else wire_view(value)
        setattr(view, field.name, value)
    return view


def _has_empty(message: Message) -> bool:
    """Whether a numeric sequence in ``message`` (or inside it) holds no array yet."""
    if not getattr(message, "_has_sequences", False):
        return False
    if any(getattr(message, slot) is None for slot in message._lazy_sequences):  # type: ignore[attr-defined]
        return True
    for attr, ftype in zip(message._fields, message._field_types, strict=True):
        if ftype.is_primitive or not getattr(message._field_classes[attr], "_has_sequences", False):
            continue
        value = getattr(message, attr)
        if any(_has_empty(v) for v in (value if ftype.is_array else [value])):
            return True
    return False


def _byte_array(value: Any, where: str) -> Any:
    """A byte array as rosbags' int8 array (:data:`EMPTY` when empty: no numpy needed)."""
    try:
        joined = b"".join(value)
    except TypeError:
        joined = b""
    if len(joined) != len(value):  # an item set by hand that is not one byte
        joined = b"".join(to_byte(v, f"{where}[{i}]") for i, v in enumerate(value))
    return np.frombuffer(joined, dtype=np.int8) if joined else EMPTY
