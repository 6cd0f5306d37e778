"""Parse .msg and .srv text into plain data, with ``file:line:col`` errors.

Why our own parser: rosbags' parser accepts typos, reports character offsets and keeps no
default values; rosidl's needs ROS installed. The grammar follows rosidl_adapter: one field
(``type name [default]``) or constant (``type NAME=value``) per line, ``#`` comments, array
suffixes ``[N]`` / ``[<=N]`` / ``[]``, bounded strings ``string<=N``, services split at a
``---`` line, actions in three parts (goal, result, feedback) at two ``---`` lines. Type
references are returned as written (qualified to ``pkg/msg/Name`` where the text says which
package); resolving them against the search path is ``registry``'s job.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.idl.errors import InterfaceError
from rosl.idl.names import CONSTANT_NAME, FIELD_NAME, PACKAGE_NAME, TYPE_NAME, did_you_mean

if TYPE_CHECKING:
    import os

INTEGER_RANGES: dict[str, tuple[int, int]] = {
    "int8": (-(2**7), 2**7 - 1),
    "uint8": (0, 2**8 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
    "byte": (0, 255),
    "char": (0, 255),
}
FLOATS = ("float32", "float64")
PRIMITIVES = ("bool", *INTEGER_RANGES, *FLOATS, "string")
BUILTIN_ALIASES = {
    "time": "builtin_interfaces/msg/Time",
    "duration": "builtin_interfaces/msg/Duration",
}
UNSUPPORTED = ("wstring", "wchar")
# The largest fixed arrays a definition may declare. A fixed array is filled at construction:
# 2**26 numbers (64 MiB of uint8, 512 MiB of float64) is far beyond any real message; strings
# and messages are one Python object each, and the CDR code is written out per element.
MAX_FIXED_NUMBERS = 2**26
MAX_FIXED_OBJECTS = 2**16
SEPARATOR = "---"


class ArrayKind(enum.Enum):
    """How many values a field holds."""

    NONE = "none"
    FIXED = "fixed"
    BOUNDED = "bounded"
    UNBOUNDED = "unbounded"


@dataclass(frozen=True, slots=True)
class FieldType:
    """The type of a field: a primitive or a message reference, maybe an array of it.

    Attributes:
        base: a primitive name (``float64``) or a message type (``pkg/msg/Name``).
        array: the array kind.
        size: the fixed length, or the bound of a bounded sequence; 0 otherwise.
        string_bound: the bound of a bounded string (or of each string element); 0 if none.
    """

    base: str
    array: ArrayKind = ArrayKind.NONE
    size: int = 0
    string_bound: int = 0

    @property
    def is_primitive(self) -> bool:
        """Whether the element type is a primitive."""
        return "/" not in self.base

    @property
    def is_array(self) -> bool:
        """Whether the field holds several values."""
        return self.array is not ArrayKind.NONE

    def element(self) -> FieldType:
        """Return the type of one element."""
        return FieldType(self.base, string_bound=self.string_bound)

    def __str__(self) -> str:
        text = self.base
        if self.string_bound:
            text += f"<={self.string_bound}"
        if self.array is ArrayKind.FIXED:
            text += f"[{self.size}]"
        elif self.array is ArrayKind.BOUNDED:
            text += f"[<={self.size}]"
        elif self.array is ArrayKind.UNBOUNDED:
            text += "[]"
        return text


@dataclass(frozen=True, slots=True)
class Field:
    """One field of a message; ``line``/``col`` locate its type token."""

    name: str
    type: FieldType
    default: Any = None
    line: int = 0
    col: int = 0
    written: str = ""


@dataclass(frozen=True, slots=True)
class Constant:
    """One constant of a message."""

    name: str
    type: str
    value: bool | int | float | str
    line: int = 0


@dataclass(frozen=True, slots=True)
class MessageSpec:
    """A parsed message (or one half of a service)."""

    type_name: str
    fields: tuple[Field, ...]
    constants: tuple[Constant, ...]
    path: str | None = None
    text: str = ""


@dataclass(frozen=True, slots=True)
class ServiceSpec:
    """A parsed service: its request and response messages."""

    type_name: str
    request: MessageSpec
    response: MessageSpec
    path: str | None = None
    text: str = ""


@dataclass(frozen=True, slots=True)
class ActionSpec:
    """A parsed action: its goal, result and feedback messages."""

    type_name: str
    goal: MessageSpec
    result: MessageSpec
    feedback: MessageSpec
    path: str | None = None
    text: str = ""

    @property
    def parts(self) -> tuple[MessageSpec, MessageSpec, MessageSpec]:
        """Goal, result and feedback, in the file's order."""
        return (self.goal, self.result, self.feedback)


@dataclass(slots=True)
class _Context:
    package: str
    path: str | os.PathLike[str] | None
    line: int = 0
    names: dict[str, int] = field(default_factory=dict)

    def error(self, message: str, col: int = 0) -> InterfaceError:
        return InterfaceError(message, self.path, self.line, col)


def split_comment(line: str) -> tuple[str, str | None]:
    """Split a line into its code and its comment (text after an unquoted ``#``)."""
    quote = ""
    for index, char in enumerate(line):
        if quote:
            if char == quote and line[index - 1] != "\\":
                quote = ""
        elif char in "'\"":
            quote = char
        elif char == "#":
            return line[:index], line[index + 1 :]
    return line, None


def parse_message(
    text: str, type_name: str, path: str | os.PathLike[str] | None = None, first_line: int = 1
) -> MessageSpec:
    """Parse the text of a .msg file (or one side of a .srv).

    Args:
        text: the definition text.
        type_name: the canonical name it defines, ``pkg/msg/Name``.
        path: the file, for error locations.
        first_line: the line number of the text's first line within the file.

    Returns:
        The parsed message.

    Raises:
        InterfaceError: the text is not a valid definition; the error names file:line:col.
    """
    ctx = _Context(package=type_name.split("/", 1)[0], path=path)
    fields: list[Field] = []
    constants: list[Constant] = []
    constant_lines: dict[str, int] = {}
    for offset, raw in enumerate(text.splitlines()):
        ctx.line = first_line + offset
        code, _ = split_comment(raw)
        if not code.strip():
            continue
        if code.strip() == SEPARATOR:
            raise ctx.error(
                "'---' separates a service's request from its response; "
                "a .msg file cannot contain it",
                code.index("-") + 1,
            )
        item = _parse_line(code, ctx)
        if isinstance(item, Constant):
            if item.name in constant_lines:
                raise ctx.error(
                    f"duplicate constant '{item.name}' "
                    f"(first defined on line {constant_lines[item.name]})",
                    code.index(item.name) + 1,
                )
            constant_lines[item.name] = ctx.line
            constants.append(item)
        else:
            if item.name in ctx.names:
                raise ctx.error(
                    f"duplicate field '{item.name}' (first defined on line {ctx.names[item.name]})",
                    code.index(item.name, item.col - 1 + len(item.written)) + 1,
                )
            ctx.names[item.name] = ctx.line
            fields.append(item)
    return MessageSpec(
        type_name, tuple(fields), tuple(constants), str(path) if path else None, text
    )


def parse_service(
    text: str, type_name: str, path: str | os.PathLike[str] | None = None
) -> ServiceSpec:
    """Parse the text of a .srv file into its request and response.

    Args:
        text: the definition text.
        type_name: the canonical name, ``pkg/srv/Name``.
        path: the file, for error locations.

    Returns:
        The parsed service; either side may be empty.

    Raises:
        InterfaceError: no separator, more than one, or a bad line on either side.
    """
    lines = text.splitlines()
    separators = [i for i, raw in enumerate(lines) if split_comment(raw)[0].strip() == SEPARATOR]
    if not separators:
        raise InterfaceError(
            "a service needs a line '---' between its request and its response fields",
            path,
            len(lines) or 1,
        )
    if len(separators) > 1:
        raise InterfaceError(
            f"more than one '---' in a service (the first is on line {separators[0] + 1}); "
            "a .srv file has one request part and one response part",
            path,
            separators[1] + 1,
            1,
        )
    cut = separators[0]
    request = parse_message("\n".join(lines[:cut]), f"{type_name}_Request", path, 1)
    response = parse_message("\n".join(lines[cut + 1 :]), f"{type_name}_Response", path, cut + 2)
    return ServiceSpec(type_name, request, response, str(path) if path else None, text)


def parse_action(
    text: str, type_name: str, path: str | os.PathLike[str] | None = None
) -> ActionSpec:
    """Parse the text of an .action file into its goal, result and feedback.

    Args:
        text: the definition text.
        type_name: the canonical name, ``pkg/action/Name``.
        path: the file, for error locations.

    Returns:
        The parsed action; any part may be empty.

    Raises:
        InterfaceError: not exactly two separators, or a bad line in any part.
    """
    lines = text.splitlines()
    separators = [i for i, raw in enumerate(lines) if split_comment(raw)[0].strip() == SEPARATOR]
    if len(separators) < 2:
        found = "no '---' line" if not separators else f"one '---' (line {separators[0] + 1})"
        raise InterfaceError(
            f"an action has three parts, goal, result and feedback, separated by two '---' "
            f"lines; this file has {found}",
            path,
            len(lines) or 1,
        )
    if len(separators) > 2:
        raise InterfaceError(
            f"more than two '---' in an action (the others are on lines {separators[0] + 1} and "
            f"{separators[1] + 1}); an .action file has goal, result and feedback parts",
            path,
            separators[2] + 1,
            1,
        )
    first, second = separators
    parts = []
    for suffix, start, end in (
        ("_Goal", 0, first), ("_Result", first + 1, second), ("_Feedback", second + 1, len(lines))
    ):  # fmt: skip
        parts.append(
            parse_message("\n".join(lines[start:end]), f"{type_name}{suffix}", path, start + 1)
        )
    goal, result, feedback = parts
    return ActionSpec(type_name, goal, result, feedback, str(path) if path else None, text)


def _parse_line(code: str, ctx: _Context) -> Field | Constant:
    type_col = len(code) - len(code.lstrip()) + 1
    body = code.strip()
    type_token, _, rest = body.partition(" ")
    rest_col = type_col + len(type_token) + 1 + (len(rest) - len(rest.lstrip()))
    rest = rest.strip()
    # a constant reads 'type NAME=value' (spaces allowed around '=')
    name_part, eq, value_part = rest.partition("=")
    if eq and name_part.strip() and " " not in name_part.strip():
        eq_index = code.index("=", rest_col - 1)
        value_col = eq_index + 2 + len(value_part) - len(value_part.lstrip())
        return _parse_constant(
            type_token, type_col, name_part.strip(), rest_col, ctx, value_part, value_col
        )
    if not rest:
        raise ctx.error(f"expected a field name after the type '{type_token}'", type_col)
    ftype = parse_field_type(type_token, type_col, ctx)
    name, _, default_text = rest.partition(" ")
    if not FIELD_NAME.match(name):
        raise ctx.error(
            f"invalid field name '{name}': use lowercase letters, digits and single "
            "underscores, starting with a letter",
            rest_col,
        )
    default = None
    default_text = default_text.strip()
    if default_text:
        default_col = code.index(default_text, rest_col - 1 + len(name)) + 1
        if not ftype.is_primitive:
            raise ctx.error(
                f"field '{name}' has a default value, but only primitive fields can have one",
                default_col,
            )
        default = parse_value(ftype, default_text, default_col, ctx)
    return Field(name, ftype, default, ctx.line, type_col, type_token)


def _parse_constant(
    type_token: str,
    type_col: int,
    name: str,
    name_col: int,
    ctx: _Context,
    value_text: str,
    value_col: int,
) -> Constant:
    ftype = parse_field_type(type_token, type_col, ctx)
    if not ftype.is_primitive or ftype.is_array:
        raise ctx.error(
            f"constant '{name}' must have a primitive, non-array type, not '{type_token}'",
            type_col,
        )
    if not CONSTANT_NAME.match(name):
        raise ctx.error(
            f"invalid constant name '{name}': use capital letters, digits and single "
            "underscores, starting with a letter",
            name_col,
        )
    value_text = value_text.strip()
    if not value_text:
        raise ctx.error(f"constant '{name}' has no value after '='", name_col)
    value = parse_value(ftype, value_text, value_col, ctx)
    return Constant(name, ftype.base, value, ctx.line)


def parse_field_type(token: str, col: int, ctx: _Context) -> FieldType:
    """Parse a type token such as ``float64[<=3]``, ``string<=8`` or ``geometry_msgs/Point[]``."""
    base, array, size = token, ArrayKind.NONE, 0
    if token.endswith("]"):
        open_at = token.rfind("[")
        if open_at < 0:
            raise ctx.error(f"type '{token}' ends with ']' but has no '['", col)
        base, inside = token[:open_at], token[open_at + 1 : -1]
        bound_col = col + open_at + 1
        if not inside:
            array = ArrayKind.UNBOUNDED
        else:
            array = ArrayKind.BOUNDED if inside.startswith("<=") else ArrayKind.FIXED
            size = _positive(inside.removeprefix("<="), token, bound_col, "array bound", ctx)
    elif "[" in token:
        raise ctx.error(f"type '{token}' has '[' but no closing ']'", col + token.index("["))
    string_bound = 0
    if base.startswith(("string<=", "wstring<=")):
        head, _, bound = base.partition("<=")
        string_bound = _positive(bound, token, col + len(head) + 2, "string bound", ctx)
        base = head
    resolved = _resolve_base(base, col, ctx)
    if array is ArrayKind.FIXED:
        numbers = resolved in PRIMITIVES and resolved != "string"
        limit = MAX_FIXED_NUMBERS if numbers else MAX_FIXED_OBJECTS
        if size > limit:
            kind = "numbers" if numbers else "strings" if resolved == "string" else "messages"
            raise ctx.error(
                f"fixed array '{token}' is too large: {size} elements, at most {limit} for "
                f"{kind} (use a sequence '{token[:open_at]}[]' for big data)",
                bound_col,
            )
    return FieldType(resolved, array, size, string_bound)


def _positive(text: str, token: str, col: int, what: str, ctx: _Context) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value <= 0:
        shown = text or "nothing"
        raise ctx.error(
            f"bad {what} '{shown}' in '{token}': expected a whole number greater than 0"
            + (", optionally after '<='" if what == "array bound" else ""),
            col,
        )
    return value


def _resolve_base(base: str, col: int, ctx: _Context) -> str:
    if base in PRIMITIVES:
        return base
    if base in BUILTIN_ALIASES:
        return BUILTIN_ALIASES[base]
    if base in UNSUPPORTED:
        raise ctx.error(f"type '{base}' is not supported by rosl; use 'string'", col)
    parts = base.split("/")
    if len(parts) == 1:
        if TYPE_NAME.match(base):
            return f"{ctx.package}/msg/{base}"
        raise ctx.error(f"unknown type '{base}'{did_you_mean(base, PRIMITIVES)}", col)
    if len(parts) == 3 and parts[1] == "msg":
        parts = [parts[0], parts[2]]
    if len(parts) != 2 or not PACKAGE_NAME.match(parts[0]) or not TYPE_NAME.match(parts[1]):
        raise ctx.error(
            f"invalid type '{base}': expected a primitive, 'Name' or 'package/Name'", col
        )
    return f"{parts[0]}/msg/{parts[1]}"


def parse_value(ftype: FieldType, text: str, col: int, ctx: _Context) -> Any:
    """Parse a constant or default value for ``ftype``, checking ranges and array lengths."""
    if not ftype.is_array:
        return _parse_scalar(ftype.base, ftype.string_bound, text, col, ctx)
    if not (text.startswith("[") and text.endswith("]")):
        raise ctx.error(
            f"the default of an array field must be written '[a, b, ...]', got {text}", col
        )
    inner = text[1:-1]
    items = (
        _split_strings(inner, col, ctx)
        if ftype.base == "string"
        else ([t.strip() for t in inner.split(",")] if inner.strip() else [])
    )
    if ftype.array is ArrayKind.FIXED and len(items) != ftype.size:
        raise ctx.error(
            f"'{ftype}' needs exactly {ftype.size} values, the default has {len(items)}", col
        )
    if ftype.array is ArrayKind.BOUNDED and len(items) > ftype.size:
        raise ctx.error(
            f"'{ftype}' holds at most {ftype.size} values, the default has {len(items)}", col
        )
    return [_parse_scalar(ftype.base, ftype.string_bound, item, col, ctx) for item in items]


def _parse_scalar(base: str, string_bound: int, text: str, col: int, ctx: _Context) -> Any:
    if base == "bool":
        lowered = text.lower()
        if lowered not in ("true", "false", "1", "0"):
            raise ctx.error(f"bool value must be true, false, 1 or 0, not '{text}'", col)
        return lowered in ("true", "1")
    if base in INTEGER_RANGES:
        try:
            value = int(text, 0) if not text.lstrip("+-").isdigit() else int(text)
        except ValueError:
            raise ctx.error(f"value '{text}' is not a whole number ({base})", col) from None
        low, high = INTEGER_RANGES[base]
        if not low <= value <= high:
            raise ctx.error(f"value {value} is out of range for {base} ({low} to {high})", col)
        return value
    if base in FLOATS:
        try:
            return float(text)
        except ValueError:
            raise ctx.error(f"value '{text}' is not a number ({base})", col) from None
    # string
    string = text
    for quote in ('"', "'"):
        if len(text) >= 2 and text[0] == quote and text[-1] == quote:
            string = text[1:-1].replace("\\" + quote, quote)
            break
    if string_bound and len(string) > string_bound:
        raise ctx.error(
            f"string value is {len(string)} characters long, more than its bound {string_bound}",
            col,
        )
    return string


def _split_strings(inner: str, col: int, ctx: _Context) -> list[str]:
    items: list[str] = []
    rest = inner.strip()
    while rest:
        if rest[0] in "'\"":
            quote = rest[0]
            end = 1
            while end < len(rest) and not (rest[end] == quote and rest[end - 1] != "\\"):
                end += 1
            if end >= len(rest):
                raise ctx.error(f"unterminated string in array value [{inner}]", col)
            items.append(rest[: end + 1])
            rest = rest[end + 1 :].lstrip()
        else:
            token, _, _ = rest.partition(",")
            items.append(token.strip())
            rest = rest[len(token) :].lstrip()
        if rest.startswith(","):
            rest = rest[1:].lstrip()
        elif rest:
            raise ctx.error(f"expected ',' between the values of [{inner}]", col)
    return items
