"""Messages as rosbags' generated CDR serializer reads them.

rosbags holds ``byte`` as a signed int8 and a byte array as an int8 numpy array, where rosl
holds rclpy's ``bytes`` of length 1; and a numeric sequence left empty since construction
holds no array at all (see ``sequences.py``). :func:`wire_view` gives the serializer a view
with the values it expects; messages with neither anywhere inside are returned as they are.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import TYPE_CHECKING, Any, NamedTuple

from rosl.idl.messages import to_byte
from rosl.idl.sequences import EMPTY

if TYPE_CHECKING:
    from collections.abc import Callable

    import numpy as np

    from rosl.idl.base import Message
else:
    from rosl.idl.lazy_numpy import np


class _Plan(NamedTuple):
    """What :func:`wire_view` needs of a message class, worked out once per class."""

    has_bytes: bool
    lazy: tuple[str, ...]  # the slots of numeric sequences (None until first set or read)
    nested: tuple[tuple[str, bool], ...]  # message fields that may hold such a sequence
    view: Callable[[Any], SimpleNamespace]  # the view of one message (see _view_function)


_plans: dict[type, _Plan | None] = {}


def wire_view(message: Message) -> Any:
    """Return ``message`` as rosbags' CDR serializer reads it.

    Raises:
        FieldError: a byte field holds something that is not a byte (named by its path).
    """
    cls = type(message)
    plan = _plans[cls] if cls in _plans else _plan_of(cls)
    if plan is None or (not plan.has_bytes and not _has_empty(message, plan)):
        return message
    return plan.view(message)


def _has_empty(message: Message, plan: _Plan) -> bool:
    """Whether a numeric sequence in ``message`` (or inside it) holds no array yet."""
    for slot in plan.lazy:
        if getattr(message, slot) is None:
            return True
    for attr, is_array in plan.nested:
        value = getattr(message, attr)
        for item in value if is_array else (value,):
            cls = type(item)
            inner = _plans[cls] if cls in _plans else _plan_of(cls)
            if inner is not None and _has_empty(item, inner):
                return True
    return False


def _plan_of(cls: type) -> _Plan | None:
    """Work out (and keep) how :func:`wire_view` reads messages of ``cls``."""
    spec = getattr(cls, "_spec", None)
    if spec is None:  # not one of our message classes: read as it is
        _plans[cls] = None
        return None
    lazy: tuple[str, ...] = getattr(cls, "_lazy_sequences", ())
    field_classes: dict[str, type] = getattr(cls, "_field_classes", {})
    nested = []
    for attr, ftype in zip(getattr(cls, "_fields", ()), spec.fields, strict=True):
        inner = field_classes.get(attr)
        if inner is not None and getattr(inner, "_has_sequences", False):
            nested.append((attr, ftype.type.is_array))
    plan = _Plan(bool(getattr(cls, "_has_bytes", False)), lazy, tuple(nested), _view_function(cls))
    _plans[cls] = plan
    return plan


def _view_function(cls: Any) -> Callable[[Any], SimpleNamespace]:
    """Write and compile the function making the view of one message of ``cls``.

    One expression per field, as rosbags reads it (by its Python attribute name): a numeric
    sequence not made yet as :data:`EMPTY`, a byte as rosbags' int, a byte array as its int8
    array, a nested message as its own view (or itself, when its class needs none).
    """
    namespace: dict[str, Any] = {
        "SimpleNamespace": SimpleNamespace, "EMPTY": EMPTY, "wire_view": wire_view,
        "to_byte": to_byte, "byte_array": _byte_array,
    }  # fmt: skip
    items = []
    for index, (attr, ftype) in enumerate(zip(cls._fields, cls._field_types, strict=True)):
        where = f"W{index}"
        namespace[where] = f"{cls.__msgtype__}.{attr}"  # an error names the field
        if "_" + attr in cls._lazy_sequences:
            value = f"EMPTY if m._{attr} is None else m.{attr}"
        elif ftype.base == "byte" and ftype.is_array:
            value = f"byte_array(m.{attr}, {where})"
        elif ftype.base == "byte":
            value = f"int.from_bytes(to_byte(m.{attr}, {where}), 'little', signed=True)"
        elif ftype.is_primitive:
            value = f"m.{attr}"
        elif ftype.is_array:
            value = f"[wire_view(v) for v in m.{attr}]"
        else:
            inner = cls._field_classes[attr]
            special = getattr(inner, "_has_bytes", True) or getattr(inner, "_has_sequences", True)
            namespace[f"C{index}"] = None if special else inner  # read as it is: no view
            value = f"v if type(v := m.{attr}) is C{index} else wire_view(v)"
        items.append(f"{attr!r}: {value}")
    source = f"def view(m):\n    return SimpleNamespace(**{{{', '.join(items)}}})\n"
    exec(compile(source, f"<rosl wire view {cls.__msgtype__}>", "exec"), namespace)
    view: Callable[[Any], SimpleNamespace] = namespace["view"]
    return view


def _byte_array(value: Any, where: str) -> Any:
    """A byte array as rosbags' int8 array (:data:`EMPTY` when empty: no numpy needed)."""
    try:
        joined = b"".join(value)
    except TypeError:
        joined = b""
    if len(joined) != len(value):  # an item set by hand that is not one byte
        joined = b"".join(to_byte(v, f"{where}[{i}]") for i, v in enumerate(value))
    return np.frombuffer(joined, dtype=np.int8) if joined else EMPTY
