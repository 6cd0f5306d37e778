"""Messages to and from YAML, CSV and plain dicts, with ROS 2's formatting rules.

Output matches rosidl_runtime_py (what ``ros2 topic echo`` and ``ros2 interface proto``
print): block-style YAML in field order, strings and arrays truncated to ``truncate_length``
with ``...``, and ``--no-arr``/``--no-str`` placeholders such as
``<sequence type: double, length: 3>``.
"""

from __future__ import annotations

import sys
from collections import OrderedDict
from typing import TYPE_CHECKING, Any

import yaml

from rosl.idl.errors import InterfaceError
from rosl.idl.lazy_numpy import is_numpy
from rosl.idl.messages import Message
from rosl.idl.parser import ArrayKind, FieldType

if TYPE_CHECKING:
    from collections.abc import Mapping

# rosidl's IDL spelling of each primitive, used in the --no-arr placeholders
IDL_NAMES = {
    "bool": "boolean",
    "byte": "octet",
    "char": "uint8",
    "float32": "float",
    "float64": "double",
}


def _array_placeholder(value: Any, ftype: FieldType) -> str:
    element = IDL_NAMES.get(ftype.base, ftype.base)
    if ftype.array is ArrayKind.FIXED:
        return f"<array type: {element}[{ftype.size}]>"
    if ftype.array is ArrayKind.BOUNDED:
        return f"<sequence type: {element}[{ftype.size}], length: {len(value)}>"
    return f"<sequence type: {element}, length: {len(value)}>"


def message_to_ordered(
    message: Message,
    *,
    truncate_length: int | None = None,
    no_arr: bool = False,
    no_str: bool = False,
) -> dict[str, Any]:
    """Return the message as a dict ready for YAML, applying ROS 2's display options."""
    out: dict[str, Any] = {}
    for name, ftype in zip(message._fields, message._field_types, strict=True):
        out[name] = _convert(getattr(message, name), ftype, truncate_length, no_arr, no_str)
    return out


def _convert(
    value: Any, ftype: FieldType | None, truncate: int | None, no_arr: bool, no_str: bool
) -> Any:
    if isinstance(value, bytes):  # a byte field: its characters, as rosidl_runtime_py shows it
        if truncate is not None and len(value) > truncate:
            return "".join(map(chr, value[:truncate])) + "..."
        return "".join(map(chr, value))
    if isinstance(value, str):
        if no_str:
            return f"<string length: <{len(value)}>>"
        if truncate is not None and len(value) > truncate:
            return value[:truncate] + "..."
        return value
    if isinstance(value, (list, tuple)) or is_numpy(value, "ndarray"):
        if no_arr and ftype is not None:
            return _array_placeholder(value, ftype)
        items = value.tolist() if is_numpy(value, "ndarray") else list(value)
        if truncate is not None and len(items) > truncate:
            return [_convert(v, None, truncate, no_arr, no_str) for v in items[:truncate]] + ["..."]
        return [_convert(v, None, truncate, no_arr, no_str) for v in items]
    if is_numpy(value, "generic"):
        return value.item()
    if isinstance(value, Message):
        return message_to_ordered(value, truncate_length=truncate, no_arr=no_arr, no_str=no_str)
    return value


class _Dumper(yaml.SafeDumper):
    """PyYAML's safe dumper; dicts keep insertion (field) order."""


def dump_yaml(data: Any, *, flow_style: bool = False) -> str:
    """Dump data the way rosidl_runtime_py does (no line wrapping, unicode kept)."""
    return yaml.dump(
        data,
        Dumper=_Dumper,
        allow_unicode=True,
        width=sys.maxsize,
        default_flow_style=flow_style,
        sort_keys=False,
    )


def message_to_yaml(
    message: Message,
    *,
    truncate_length: int | None = None,
    no_arr: bool = False,
    no_str: bool = False,
    flow_style: bool = False,
) -> str:
    """Return the YAML text ``ros2 topic echo`` prints for a message (without ``---``)."""
    data = message_to_ordered(
        message, truncate_length=truncate_length, no_arr=no_arr, no_str=no_str
    )
    return dump_yaml(data, flow_style=flow_style)


def message_to_csv(
    message: Message,
    *,
    truncate_length: int | None = None,
    no_arr: bool = False,
    no_str: bool = False,
) -> str:
    """Return the comma-separated leaf values ``ros2 topic echo --csv`` prints."""
    return ",".join(
        _csv_text(getattr(message, name), ftype, truncate_length, no_arr, no_str)
        for name, ftype in zip(message._fields, message._field_types, strict=True)
    )


def value_to_csv(value: Any, *, truncate_length: int | None = None) -> str:
    """A field's value (a message, a sequence or a scalar) as ``echo --field F --csv``."""
    return _csv_text(value, None, truncate_length, False, False)


def value_to_plain(value: Any, *, truncate_length: int | None = None) -> Any:
    """A field's value as YAML data, with byte fields shown as rosidl_runtime_py does."""
    return _convert(value, None, truncate_length, False, False)


def _csv_text(
    value: Any, ftype: FieldType | None, truncate: int | None, no_arr: bool, no_str: bool
) -> str:
    if isinstance(value, (list, tuple)) or is_numpy(value, "ndarray"):
        if no_arr and ftype is not None:
            return _array_placeholder(value, ftype)
        parts: list[str] = []
        for index, item in enumerate(value):
            if truncate is not None and index >= truncate:
                parts.append("...")
                break
            parts.append(_csv_text(item, None, truncate, no_arr, no_str))
        return ",".join(parts)
    if isinstance(value, Message):
        return message_to_csv(value, truncate_length=truncate, no_arr=no_arr, no_str=no_str)
    if isinstance(value, str):
        if no_str:
            return f"<string length: <{len(value)}>>"
        if truncate is not None and len(value) > truncate:
            return value[:truncate] + "..."
    if isinstance(value, bytes):  # a byte field prints as b'2'
        if truncate is not None and len(value) > truncate:
            value = value[:truncate] + b"..."
        return str(value)
    if is_numpy(value, "generic"):
        value = value.item()
    return str(value)


def parse_yaml_mapping(text: str | None, what: str = "values") -> Mapping[str, Any]:
    """Parse the YAML a user typed for a message (``"{data: 'hi'}"``); empty means ``{}``.

    Raises:
        InterfaceError: not YAML, or not a mapping of field names to values.
    """
    if text is None or not text.strip():
        return {}
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at column {mark.column + 1}" if mark is not None else ""
        problem = getattr(err, "problem", None) or str(err).splitlines()[0]
        raise InterfaceError(f"the {what} are not valid YAML{where}: {problem}: {text}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise InterfaceError(
            f'the {what} must be a YAML mapping like "{{field: value}}", got: {text}'
        )
    return data


def message_to_ordereddict(
    message: Message,
    *,
    truncate_length: int | None = None,
    no_arr: bool = False,
    no_str: bool = False,
) -> OrderedDict[str, Any]:
    """:func:`message_to_ordered` as rosidl_runtime_py returns it: nested ``OrderedDict``s."""
    data = message_to_ordered(
        message, truncate_length=truncate_length, no_arr=no_arr, no_str=no_str
    )
    return _ordered(data)  # type: ignore[no-any-return]


def _ordered(value: Any) -> Any:
    if isinstance(value, dict):
        return OrderedDict((key, _ordered(item)) for key, item in value.items())
    if isinstance(value, list) and value and isinstance(value[0], dict):  # messages, not numbers
        return [_ordered(item) for item in value]
    return value


def message_slot_types(message: Message) -> OrderedDict[str, str]:
    """Each field's name and its type as written in ROS (``float64[3]``), in field order."""
    return OrderedDict(message.get_fields_and_field_types())
