"""Message classes generated from parsed specs: construction, dict conversion, checks.

A generated class has ``__slots__`` and a compiled ``__init__`` taking every field by keyword
or in field order (rosbags' deserializer calls ``cls(*values)``), so building a received
message costs one Python call. Numeric arrays are numpy arrays of the field's dtype; they are
properties that accept lists, tuples, ``bytes``/``bytearray``/``memoryview`` (for 8-bit
types), ``array.array`` and numpy arrays — whole, never element by element (a numpy array of
the right dtype is kept as it is; a read-only one, a view into received bytes, is copied so
that the message may be changed, as in rclpy) — and check fixed lengths and bounds on
assignment. Scalars are plain attributes: a wrong value is found
when the message is serialized (``store``), where ``check_fields`` names the field.

``byte`` is as rclpy has it: a ``bytes`` object of length 1 (``bytes([0])``), and a byte array is
a list of them; both are properties that also take 0..255 (and rosbags' signed int8, which is
how the CDR serializer reads and writes them: ``wire_view.py``). ``char`` is an int.
"""

from __future__ import annotations

import array as py_array
import keyword
import math
import operator
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

from rosl.idl.base import ActionType, Message, ServiceType
from rosl.idl.errors import FieldError
from rosl.idl.lazy_numpy import is_numpy
from rosl.idl.names import did_you_mean, parse_type_name
from rosl.idl.parser import FLOATS, INTEGER_RANGES, ArrayKind, FieldType
from rosl.idl.sequences import array_types, sequence_property

if TYPE_CHECKING:
    import numpy as np

    from rosl.idl.parser import MessageSpec
else:
    from rosl.idl.lazy_numpy import np  # loaded by the first numeric array

_FLOAT32_MAX = 3.4028234663852886e38  # the largest finite float32

__all__ = [
    "ActionType",
    "Message",
    "ServiceType",
    "build_action_class",
    "build_message_class",
    "build_service_class",
    "from_dict",
    "to_dict",
]

DTYPES: dict[str, str] = {  # numpy dtype names
    "bool": "bool",
    "char": "uint8",
    "int8": "int8",
    "uint8": "uint8",
    "int16": "int16",
    "uint16": "uint16",
    "int32": "int32",
    "uint32": "uint32",
    "int64": "int64",
    "uint64": "uint64",
    "float32": "float32",
    "float64": "float64",
}
_ZERO: dict[str, Any] = {"bool": False, "string": "", **dict.fromkeys(FLOATS, 0.0)}
DUMMY_FIELD = "structure_needs_at_least_one_member"


_BYTES = tuple(bytes((i,)) for i in range(256))  # each byte value once, shared


def _scalar_default(ftype: FieldType, default: Any) -> Any:
    if ftype.base == "byte":
        return _BYTES[(default or 0) & 0xFF]
    if default is not None:
        return default
    return _ZERO.get(ftype.base, 0)


def to_byte(value: Any, where: str) -> bytes:
    """Return a ``byte`` value as rclpy holds it (``bytes`` of length 1).

    Takes bytes of length 1, a whole number from -128 (rosbags' int8) to 255, or a string of
    one character up to U+00FF (what ``ros2 topic echo`` prints for a byte).

    Raises:
        FieldError: anything else, naming ``where``.
    """
    if isinstance(value, (bytes, bytearray)) and len(value) == 1:
        return _BYTES[value[0]]
    if (isinstance(value, int) or is_numpy(value, "integer")) and not (
        isinstance(value, bool) or is_numpy(value, "bool_")
    ):
        if -128 <= value <= 255:
            return _BYTES[int(value) & 0xFF]
    elif isinstance(value, str) and len(value) == 1 and ord(value) <= 255:
        return _BYTES[ord(value)]
    raise FieldError(
        f"{where}: expects a byte (bytes of length 1, or 0 to 255), got {_show(value)}"
    )


def _byte_coercer(where: str) -> Callable[[Any], bytes]:
    return lambda value: to_byte(value, where)


def byte_array_coercer(ftype: FieldType, where: str) -> Callable[[Any], list[bytes]]:
    """Return a function turning user values into a byte array field's list of bytes."""

    def coerce(value: Any) -> list[bytes]:
        if value is None:
            items = [_BYTES[0]] * (ftype.size if ftype.array is ArrayKind.FIXED else 0)
        elif isinstance(value, (bytes, bytearray, memoryview)):
            items = [_BYTES[b] for b in bytes(value)]
        elif is_numpy(value, "ndarray") and value.ndim == 1 and value.dtype.kind in "iu":
            if value.size and (int(value.min()) < -128 or int(value.max()) > 255):
                raise FieldError(f"{where}: values must lie in 0 to 255 for byte")
            items = [_BYTES[b] for b in value.astype(np.int64).astype(np.uint8).tobytes()]
        elif isinstance(value, (list, tuple)):
            items = [to_byte(v, f"{where}[{i}]") for i, v in enumerate(value)]
        else:
            raise FieldError(f"{where}: expects a list of byte, got {_show(value)}")
        check_length(ftype, len(items), where)
        return items

    return coerce


def array_coercer(ftype: FieldType, where: str) -> Callable[[Any], Any]:
    """Return a function turning user values into a numpy array for a numeric array field."""
    dtype_name = DTYPES[ftype.base]
    dtype: Any = None  # numpy's, at the first value (building the class does not load numpy)
    kinds = "b" if ftype.base == "bool" else "iu" if ftype.base in INTEGER_RANGES else "biuf"
    low, high = INTEGER_RANGES.get(ftype.base, (0, 0))
    eight_bit = ftype.base in ("uint8", "char")

    def coerce(value: Any) -> Any:
        nonlocal dtype
        if dtype is None:
            dtype = np.dtype(dtype_name)
        if value is None:
            return np.zeros(ftype.size if ftype.array is ArrayKind.FIXED else 0, dtype)
        if type(value) in array_types() and value.dtype == dtype and value.ndim == 1:
            array = value.view(np.ndarray)
            if not array.flags.writeable:  # a view into received bytes: a copy the user may change
                array = array.copy()
        elif eight_bit and isinstance(value, (bytes, bytearray, memoryview)):
            array = np.frombuffer(value, dtype=np.uint8).astype(dtype)  # one copy, no loop
        elif isinstance(value, py_array.array) and np.dtype(value.typecode) == dtype:
            array = np.frombuffer(value, dtype=dtype).copy()  # rclpy's array.array, as is
        else:
            raw = np.asarray(value)
            if kinds == "iu" and raw.dtype.kind in "fO" and raw.ndim == 1 and raw.size:
                # numpy guesses float64 for ints beyond int64: check the Python ints exactly
                items = [] if isinstance(value, np.ndarray) else list(value)
                if not items or not all(
                    isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in items
                ):
                    raise FieldError(f"{where}: expects a list of {ftype.base}, got {_show(value)}")
                if min(items) < low or max(items) > high:
                    raise FieldError(
                        f"{where}: values must lie in {low} to {high} for {ftype.base}"
                    )
                raw = np.array(items, dtype=np.uint64 if min(items) >= 0 else np.int64)
            if raw.size == 0:
                array = np.zeros(0, dtype)
            elif raw.ndim != 1 or raw.dtype.kind not in kinds:
                raise FieldError(f"{where}: expects a list of {ftype.base}, got {_show(value)}")
            else:
                if kinds == "iu" and (int(raw.min()) < low or int(raw.max()) > high):
                    raise FieldError(
                        f"{where}: values must lie in {low} to {high} for {ftype.base}"
                    )
                array = raw.astype(dtype)
        check_length(ftype, len(array), where)
        return array

    return coerce


def _show(value: Any) -> str:
    text = repr(value)
    return f"{type(value).__name__} {text[:40] + '...' if len(text) > 40 else text}"


def build_message_class(
    spec: MessageSpec, field_classes: dict[str, type[Message]]
) -> type[Message]:
    """Generate the class for a parsed, resolved message.

    Args:
        spec: the message, with every type reference resolved to ``pkg/msg/Name``.
        field_classes: the classes of the message types its fields refer to.

    Returns:
        The new class, a subclass of :class:`Message`.
    """
    name = parse_type_name(spec.type_name)
    namespace: dict[str, Any] = {"_unknown_fields": _unknown_fields}
    body: dict[str, Any] = {}
    slots: list[str] = []
    lazy: list[str] = []  # the slots of numeric sequences (None while empty, see sequences.py)
    params: list[str] = []
    lines: list[str] = []
    for index, field in enumerate(spec.fields):
        ftype = field.type
        where = f"{spec.type_name} field '{field.name}'"
        attr = _attr_name(field.name)
        if ftype.base == "byte":
            coerce_byte: Callable[[Any], Any] = (
                byte_array_coercer(ftype, where) if ftype.is_array else _byte_coercer(where)
            )
            namespace[f"_d{index}"] = (
                field.default if ftype.is_array else _scalar_default(ftype, field.default)
            )
            slots.append("_" + attr)
            body[attr] = _array_property("_" + attr, coerce_byte)
            params.append(f"{attr}={'None' if ftype.is_array else f'_d{index}'}")
            lines.append(
                f"    self.{attr} = _d{index} if {attr} is None else {attr}"
                if ftype.is_array
                else f"    self.{attr} = {attr}"
            )
            continue
        if ftype.is_primitive and ftype.base != "string" and ftype.is_array:
            coerce = array_coercer(ftype, where)
            default = None if field.default is None else list(field.default)
            namespace[f"_d{index}"] = default
            slots.append("_" + attr)
            if ftype.array is not ArrayKind.FIXED:
                lazy.append("_" + attr)
            body[attr] = (
                _array_property("_" + attr, coerce)
                if ftype.array is ArrayKind.FIXED
                else sequence_property("_" + attr, attr, coerce)
            )
            params.append(f"{attr}=None")
            lines.append(f"    self.{attr} = _d{index} if {attr} is None else {attr}")
            continue
        slots.append(attr)
        if ftype.is_primitive and not ftype.is_array:
            namespace[f"_d{index}"] = _scalar_default(ftype, field.default)
            params.append(f"{attr}=_d{index}")
            lines.append(f"    self.{attr} = {attr}")
        elif ftype.is_primitive:  # string arrays: only fixed ones are filled, as in rclpy
            filled = [""] * ftype.size if ftype.array is ArrayKind.FIXED else []
            default = list(field.default if field.default is not None else filled)
            namespace[f"_d{index}"] = default
            params.append(f"{attr}=None")
            lines.append(f"    self.{attr} = list(_d{index}) if {attr} is None else {attr}")
        else:
            namespace[f"_c{index}"] = field_classes[ftype.base]
            params.append(f"{attr}=None")
            if not ftype.is_array:
                lines.append(f"    self.{attr} = _c{index}() if {attr} is None else {attr}")
            elif ftype.array is ArrayKind.FIXED:
                lines.append(
                    f"    self.{attr} = [_c{index}() for _ in range({ftype.size})] "
                    f"if {attr} is None else {attr}"
                )
            else:
                lines.append(f"    self.{attr} = [] if {attr} is None else {attr}")
    if not spec.fields:
        params.append("_dummy=0")
        body[DUMMY_FIELD] = 0
    source = (
        f"def __init__(self, {', '.join([*params, '**_unknown'])}):\n"
        "    if _unknown:\n        _unknown_fields(self, _unknown)\n"
        + ("\n".join(lines) or "    pass")
        + "\n"
    )
    exec(compile(source, f"<rosl message {spec.type_name}>", "exec"), namespace)
    body.update(
        __slots__=(*slots, "__weakref__"),  # a sequence field's array refers back weakly
        __init__=namespace["__init__"],
        __msgtype__=spec.type_name,
        __module__=f"{name.package}.{name.kind}",
        __qualname__=name.name,
        __doc__=f"The ROS message type {spec.type_name}.",
        _fields=tuple(_attr_name(f.name) for f in spec.fields),
        _field_types=tuple(f.type for f in spec.fields),
        _field_classes={
            _attr_name(f.name): field_classes[f.type.base]
            for f in spec.fields
            if not f.type.is_primitive
        },
        _python_name=name.python_name,
        _spec=spec,
    )
    for constant in spec.constants:
        value = constant.value
        body[constant.name] = (
            _BYTES[value & 0xFF] if isinstance(value, int) and (constant.type == "byte") else value
        )
    for field in spec.fields:
        if field.default is not None:
            default = field.default
            if field.type.base == "byte":
                default = (
                    byte_array_coercer(field.type, "")(default)
                    if field.type.is_array
                    else (_scalar_default(field.type, default))
                )
            body[f"{field.name.upper()}__DEFAULT"] = default
    body["_has_bytes"] = any(f.type.base == "byte" for f in spec.fields) or any(
        getattr(c, "_has_bytes", False) for c in field_classes.values()
    )
    body["_lazy_sequences"] = tuple(lazy)
    body["_has_sequences"] = bool(lazy) or any(
        getattr(c, "_has_sequences", False) for c in field_classes.values()
    )
    return type(name.name, (Message,), body)


def _attr_name(field_name: str) -> str:
    return f"{field_name}_" if keyword.iskeyword(field_name) else field_name


def _array_property(slot: str, coerce: Callable[[Any], Any]) -> property:
    def setter(self: Message, value: Any) -> None:
        object.__setattr__(self, slot, coerce(value))

    return property(operator.attrgetter(slot), setter)


def _unknown_fields(message: Message, unknown: Mapping[str, Any]) -> None:
    bad = sorted(unknown)[0]
    raise FieldError(
        f"{message.__msgtype__} has no field '{bad}'{did_you_mean(bad, message._fields)}; "
        f"its fields are: {', '.join(message._fields) or '(none)'}"
    )


def build_service_class(
    type_name: str, request: type[Message], response: type[Message]
) -> type[ServiceType]:
    """Generate the class for a service, holding its ``Request`` and ``Response`` classes."""
    name = parse_type_name(type_name, "srv")
    return type(
        name.name,
        (ServiceType,),
        {
            "__srvtype__": type_name,
            "__module__": f"{name.package}.{name.kind}",
            "__qualname__": name.name,
            "__doc__": f"The ROS service type {type_name}.",
            "Request": request,
            "Response": response,
        },
    )


def build_action_class(
    type_name: str,
    messages: dict[str, type[Message]],
    services: dict[str, type[ServiceType]],
    cancel_goal: type[ServiceType],
    goal_status_array: type[Message],
) -> type[ActionType]:
    """Generate the class for an action from its generated message and service classes.

    Args:
        type_name: ``pkg/action/Name``.
        messages: the classes of ``_Goal``, ``_Result``, ``_Feedback``, ``_FeedbackMessage``.
        services: the classes of ``_SendGoal`` and ``_GetResult``.
        cancel_goal: action_msgs' CancelGoal service.
        goal_status_array: action_msgs' GoalStatusArray message.
    """
    name = parse_type_name(type_name, "action")
    impl = type(
        "Impl",
        (),
        {
            "__qualname__": f"{name.name}.Impl",
            "__module__": f"{name.package}.action",
            "SendGoalService": services["_SendGoal"],
            "GetResultService": services["_GetResult"],
            "FeedbackMessage": messages["_FeedbackMessage"],
            "CancelGoalService": cancel_goal,
            "GoalStatusMessage": goal_status_array,
        },
    )
    return type(
        name.name,
        (ActionType,),
        {
            "__actiontype__": type_name,
            "__module__": f"{name.package}.action",
            "__qualname__": name.name,
            "__doc__": f"The ROS action type {type_name}.",
            "Goal": messages["_Goal"],
            "Result": messages["_Result"],
            "Feedback": messages["_Feedback"],
            "Impl": impl,
        },
    )


# --- plain data -------------------------------------------------------------------------------


def to_dict(message: Message) -> dict[str, Any]:
    """Return the message as nested plain dicts, lists and scalars (field order kept)."""
    return {name: to_plain(getattr(message, name)) for name in message._fields}


def to_plain(value: Any) -> Any:
    """Convert one field value to plain Python data."""
    if isinstance(value, Message):
        return to_dict(value)
    if is_numpy(value, "ndarray"):
        return value.tolist()
    if isinstance(value, list):
        return [to_plain(v) for v in value]
    if is_numpy(value, "generic"):
        return value.item()
    return value


def from_dict(cls: type[Message], data: Mapping[str, Any] | None) -> Message:
    """Build a message from plain data; missing fields keep their defaults.

    Raises:
        FieldError: a key that is not a field, or a value the field cannot hold; the message
            names the field path (``linear.x``) and the expected type.
    """
    message = cls()
    fill(message, data or {})
    return message


def fill(message: Message, data: Mapping[str, Any], path: str = "") -> None:
    """Set the fields named in ``data`` on ``message`` (recursively for nested messages)."""
    if not isinstance(data, Mapping):
        raise FieldError(
            f"{path or message.__msgtype__}: expects a mapping of fields "
            f"({{field: value}}), got {_show(data)}"
        )
    types = dict(zip(message._fields, message._field_types, strict=True))
    for key, value in data.items():
        key = str(key)
        where = f"{path}.{key}" if path else key
        attr = _attr_name(key)
        if attr not in types:
            raise FieldError(
                f"{message.__msgtype__} has no field '{key}'"
                f"{did_you_mean(key, message._fields)}; its fields are: "
                f"{', '.join(message._fields) or '(none)'}"
            )
        ftype = types[attr]
        setattr(message, attr, _convert(message, attr, ftype, value, where))


def _convert(message: Message, attr: str, ftype: FieldType, value: Any, where: str) -> Any:
    if not ftype.is_primitive:
        cls = message._field_classes[attr]
        if not ftype.is_array:
            nested = getattr(message, attr)
            if isinstance(value, Message):
                return value
            fill(nested, value, where)
            return nested
        if not isinstance(value, list):
            raise FieldError(f"{where}: expects a list of {ftype.base}, got {_show(value)}")
        items = []
        for i, item in enumerate(value):
            element = cls()
            fill(element, item, f"{where}[{i}]")
            items.append(element)
        check_length(ftype, len(items), where)
        return items
    return convert_primitive(ftype, value, where)


def convert_primitive(ftype: FieldType, value: Any, where: str) -> Any:
    """Convert a plain value for a primitive field (scalar or array), or raise a FieldError."""
    if ftype.base == "byte":
        if ftype.is_array:
            return byte_array_coercer(ftype, where)(value)
        return to_byte(value, where)
    if ftype.is_array and ftype.base != "string":
        try:
            return array_coercer(ftype, where)(value)
        except FieldError:
            raise
        except (TypeError, ValueError) as err:
            raise FieldError(f"{where}: expects a list of {ftype.base} ({err})") from None
    if ftype.is_array:
        if not isinstance(value, list):
            raise FieldError(f"{where}: expects a list of strings, got {_show(value)}")
        check_length(ftype, len(value), where)
        return [convert_scalar(ftype.element(), v, f"{where}[{i}]") for i, v in enumerate(value)]
    return convert_scalar(ftype, value, where)


def check_length(ftype: FieldType, length: int, where: str) -> None:
    """Raise a FieldError naming ``where`` when an array's length breaks its bound."""
    if ftype.array is ArrayKind.FIXED and length != ftype.size:
        raise FieldError(f"{where}: needs exactly {ftype.size} values, got {length}")
    if ftype.array is ArrayKind.BOUNDED and length > ftype.size:
        raise FieldError(f"{where}: holds at most {ftype.size} values, got {length}")


def convert_scalar(ftype: FieldType, value: Any, where: str) -> Any:
    """Convert a plain value for a primitive scalar field, or raise a FieldError naming it."""
    base = ftype.base
    if base == "string":
        if isinstance(value, (dict, list)):
            raise FieldError(f"{where}: expects a string, got {_show(value)}")
        text = "" if value is None else str(value)
        if ftype.string_bound and len(text) > ftype.string_bound:
            raise FieldError(f"{where}: string longer than its bound {ftype.string_bound}")
        return text
    if base == "bool":
        if isinstance(value, bool) or (isinstance(value, int) and value in (0, 1)):
            return bool(value)
        raise FieldError(f"{where}: expects a bool (true/false), got {_show(value)}")
    if base in FLOATS:
        if isinstance(value, bool) or not (
            isinstance(value, (int, float)) or is_numpy(value, "number")
        ):
            raise FieldError(f"{where}: expects a {base} number, got {_show(value)}")
        try:
            number = float(value)
        except OverflowError:  # an int beyond any float
            raise FieldError(f"{where}: {_show(value)} is out of range for {base}") from None
        if base == "float32" and math.isfinite(number) and abs(number) > _FLOAT32_MAX:
            raise FieldError(f"{where}: {_show(value)} is out of range for {base}")
        return number  # (inf and nan are kept, as rclpy keeps them)
    if base == "byte":
        return to_byte(value, where)
    # integers
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not (isinstance(value, int) or is_numpy(value, "integer")):
        raise FieldError(f"{where}: expects a whole number ({base}), got {_show(value)}")
    low, high = INTEGER_RANGES[base]
    if not low <= int(value) <= high:
        raise FieldError(f"{where}: {value} is out of range for {base} ({low} to {high})")
    return int(value)


def check_fields(message: Message, path: str = "") -> None:
    """Check every field value of ``message`` against its type.

    Raises:
        FieldError: the first wrong value, naming its path and the expected type.
    """
    for attr, ftype in zip(message._fields, message._field_types, strict=True):
        where = f"{path}.{attr}" if path else f"{message.__msgtype__}.{attr}"
        value = getattr(message, attr)
        if not ftype.is_primitive:
            cls = message._field_classes[attr]
            values = value if ftype.is_array else [value]
            if ftype.is_array:
                if not isinstance(value, (list, tuple)):
                    raise FieldError(f"{where}: expects a list of {ftype.base}, got {_show(value)}")
                check_length(ftype, len(value), where)
            for i, item in enumerate(values):
                item_where = f"{where}[{i}]" if ftype.is_array else where
                if not isinstance(item, Message) or item._fields != cls._fields:
                    raise FieldError(f"{item_where}: expects a {ftype.base}, got {_show(item)}")
                check_fields(item, item_where)
        elif ftype.is_array and ftype.base in ("string", "byte"):
            if not isinstance(value, (list, tuple)):
                raise FieldError(f"{where}: expects a list of {ftype.base}, got {_show(value)}")
            check_length(ftype, len(value), where)
            for i, item in enumerate(value):
                _check_scalar(ftype.element(), item, f"{where}[{i}]")
        elif not ftype.is_array:
            _check_scalar(ftype, value, where)


def _check_scalar(ftype: FieldType, value: Any, where: str) -> None:
    if ftype.base == "string":
        if not isinstance(value, str):
            raise FieldError(f"{where}: expects a string, got {_show(value)}")
        if ftype.string_bound and len(value) > ftype.string_bound:
            raise FieldError(f"{where}: string longer than its bound {ftype.string_bound}")
        if not value.isascii():
            try:
                value.encode()
            except UnicodeEncodeError as err:
                raise FieldError(f"{where}: not UTF-8 text ({err.reason})") from None
        return
    if ftype.base in FLOATS and isinstance(value, str):
        raise FieldError(f"{where}: expects a {ftype.base} number, got {_show(value)}")
    if ftype.base in INTEGER_RANGES and isinstance(value, float):  # (packed as given)
        raise FieldError(f"{where}: expects a whole number ({ftype.base}), got {_show(value)}")
    convert_scalar(ftype, value, where)
