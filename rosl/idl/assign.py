"""Setting a message's fields from plain values, as rosidl_runtime_py's set_message_fields.

Nested messages come from mappings (a new message with the given fields) or from messages;
arrays of messages from lists of either. A scalar given in another Python type is converted
the way rosidl_runtime_py converts it (``int('42')``, ``str(5)``) and then range-checked.
With ``expand_header_auto`` a Header given as ``'auto'``, and with ``expand_time_now`` a Time
given as ``'now'``, become setters the caller runs with the current time.

Errors keep the built-in kinds rosidl_runtime_py raises, and name the field: an unknown field
is an ``AttributeError``, a value that is not a mapping where one is needed a ``TypeError``,
and a value a field cannot hold a ``ValueError`` (all are ``FieldError``, so one line each).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import Any

from rosl.idl.base import Message
from rosl.idl.errors import FieldError
from rosl.idl.messages import check_length, convert_primitive
from rosl.idl.names import did_you_mean

__all__ = ["FieldValueError", "UnknownFieldError", "set_message_fields"]

_HEADER = "std_msgs/msg/Header"
_TIME = "builtin_interfaces/msg/Time"
_CASTS: dict[str, Callable[[Any], Any]] = {"string": str, "bool": bool, "float32": float}
_CASTS["float64"] = float


class UnknownFieldError(FieldError, AttributeError):
    """A key that is not a field of the message."""


class FieldValueError(FieldError, ValueError):
    """A value that the field cannot hold."""


def set_message_fields(
    msg: Any,
    values: Any,
    expand_header_auto: bool = False,
    expand_time_now: bool = False,
) -> list[Callable[[Any], None]]:
    """Set the fields named in ``values`` on ``msg``.

    Returns:
        One setter per ``'auto'`` Header or ``'now'`` Time expanded; call each with a
        builtin_interfaces/msg/Time.

    Raises:
        UnknownFieldError: a key that is not a field (an ``AttributeError``).
        FieldError: ``values`` (or a nested value) is not a mapping (a ``TypeError``).
        FieldValueError: a value the field cannot hold (a ``ValueError``).
    """
    setters: list[Callable[[Any], None]] = []
    _assign(msg, values, setters, (expand_header_auto, expand_time_now), "")
    return setters


def _assign(
    msg: Message, values: Any, setters: list[Callable[[Any], None]], expand: tuple[bool, bool],
    path: str,
) -> None:  # fmt: skip
    if not isinstance(values, Mapping):
        raise FieldError(
            f"Value '{values}' is expected to be a dictionary but is a {type(values).__name__}"
        )
    types = dict(zip(msg._fields, msg._field_types, strict=True))
    for key, value in values.items():
        attr = f"{key}_" if f"{key}_" in types and key not in types else str(key)
        where = f"{path}.{key}" if path else str(key)
        if attr not in types:
            raise UnknownFieldError(
                f"{msg.__msgtype__} has no field '{key}'{did_you_mean(str(key), msg._fields)}"
            )
        ftype = types[attr]
        if ftype.is_primitive:
            setattr(msg, attr, _primitive(ftype, value, where))
            continue
        cls = msg._field_classes[attr]
        if ftype.is_array:
            if not isinstance(value, (list, tuple)):
                raise FieldValueError(f"{where}: expects a list of {ftype.base}, got {value!r}")
            items = [_nested(cls, v, setters, expand, f"{where}[{i}]") for i, v in enumerate(value)]
            try:
                check_length(ftype, len(items), where)
            except FieldError as err:
                raise FieldValueError(str(err)) from None
            setattr(msg, attr, items)
        elif expand[0] and ftype.base == _HEADER and value == "auto":
            setters.append(functools.partial(setattr, getattr(msg, attr), "stamp"))
        elif expand[1] and ftype.base == _TIME and value == "now":
            setters.append(functools.partial(setattr, msg, attr))
        else:
            setattr(msg, attr, _nested(cls, value, setters, expand, where))


def _nested(
    cls: type[Message], value: Any, setters: list[Callable[[Any], None]],
    expand: tuple[bool, bool], where: str,
) -> Message:  # fmt: skip
    if isinstance(value, Message):
        if value.__msgtype__ != cls.__msgtype__:
            raise FieldValueError(f"{where}: expects a {cls.__msgtype__}, got {value!r}")
        return value
    message = cls()
    _assign(message, value, setters, expand, where)
    return message


def _primitive(ftype: Any, value: Any, where: str) -> Any:
    cast = None if ftype.is_array else _CASTS.get(ftype.base, int if ftype.base != "byte" else None)
    try:
        if cast is not None and not isinstance(value, (list, dict)):
            value = cast(value)
        return convert_primitive(ftype, value, where)
    except FieldError as err:
        raise FieldValueError(str(err)) from None
    except (TypeError, ValueError, OverflowError) as err:
        raise FieldValueError(f"{where}: expects {ftype}, got {value!r} ({err})") from None
