"""CDR serializers for flat message types, generated as a few ``struct`` packs.

A flat type holds only scalar numbers, booleans and strings, directly or in flat nested
messages: no arrays, no bytes (``std_msgs/msg/String``, ``Header``, ``Twist``, ``Pose``,
``PoseStamped``, ``TransformStamped``...). Most small messages are. rosbags' generated
serializer, generic over every type, spends two passes (a size pass, then one ``pack_into``
call per field into a buffer) and a look-up per nested message; for such a type this module
writes one function doing the same in one pass: each run of fields between two strings is
one precompiled :class:`struct.Struct` (padding included) and the result is their
concatenation with the strings' bytes. A run after a string starts at an offset known only
then: it has eight structs, one per offset modulo 8, picked at run time.

The bytes are rosbags' (little-endian CDR with its encapsulation header): the same ``struct``
codes pack each value, so a value a field cannot hold raises what rosbags' would (the store
names the field). The tests compare both for every flat type of the installed interfaces.
Hand-written because it is the one piece rosbags' generic code makes slow for small messages.
"""

from __future__ import annotations

import struct
from typing import TYPE_CHECKING, Any

from rosl.idl.parser import ArrayKind

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.idl.base import Message

# struct codes as rosbags packs each primitive (rosbags.serde.primitives), and their sizes
_CODES = {
    "bool": "?", "char": "B", "int8": "b", "uint8": "B", "int16": "h", "uint16": "H",
    "int32": "i", "uint32": "I", "int64": "q", "uint64": "Q", "float32": "f", "float64": "d",
}  # fmt: skip
_STRING = "string"


def flat_serializer(cls: type[Message]) -> Callable[[Message], bytes] | None:
    """A serializer for messages of ``cls``, or None when the type is not flat.

    The function returns the CDR bytes rosbags' ``serialize_cdr`` would (little endian); it
    raises what packing a wrong value raises (``struct.error``, ``AttributeError``...).
    """
    leaves: list[tuple[str, str]] = []  # (kind: a struct code or "string", value expression)
    setup: list[str] = []  # nested messages read into locals once
    if not _flatten(cls, "m", leaves, setup):
        return None
    return _compile(cls.__msgtype__, leaves, setup)


def _flatten(cls: Any, expr: str, leaves: list[tuple[str, str]], setup: list[str]) -> bool:
    spec = getattr(cls, "_spec", None)
    if spec is None or not spec.fields or getattr(cls, "_has_bytes", True):
        return False
    if getattr(cls, "_has_sequences", True):
        return False
    for field, attr in zip(spec.fields, cls._fields, strict=True):
        ftype = field.type
        if ftype.array is not ArrayKind.NONE:
            return False
        value = f"{expr}.{attr}"
        if not ftype.is_primitive:
            local = f"o{len(setup)}"
            setup.append(f"{local} = {value}")
            if not _flatten(cls._field_classes[attr], local, leaves, setup):
                return False
        elif ftype.base == _STRING:
            leaves.append((_STRING, value))
        elif ftype.base in _CODES:
            leaves.append((_CODES[ftype.base], value))
        else:
            return False  # byte, wstring, float128: rosbags' serializer
    return True


def _layout(codes: list[str], start: int) -> tuple[str, int]:
    """A struct format (little endian, padding as CDR aligns) for fields from offset ``start``.

    Returns the format and the offset after the last field.
    """
    fmt, pos = "<", start
    for code in codes:
        size = struct.calcsize(code)
        pad = -pos % size
        fmt += "x" * pad + code
        pos += pad + size
    return fmt, pos


def _compile(
    type_name: str, leaves: list[tuple[str, str]], setup: list[str]
) -> Callable[[Message], bytes]:
    """Write and compile the serializer of a flat type from its leaves."""
    # runs: the scalar codes up to a string (its length field ends the run), then its bytes
    runs: list[tuple[list[str], list[str], int | None]] = [([], [], None)]
    strings = 0
    for kind, value in leaves:
        codes, values, _ = runs[-1]
        if kind == _STRING:
            name = f"b{strings}"
            strings += 1
            setup.append(f"{name} = {value}.encode()")
            setup.append(f"n{strings - 1} = len({name}) + 1")  # its length field: with the NUL
            codes.append("I")
            values.append(f"n{strings - 1}")
            runs[-1] = (codes, values, strings - 1)
            runs.append(([], [], None))
        else:
            codes.append(kind)
            values.append(value)
    namespace: dict[str, Any] = {}
    body = [f"def serialize(m):  # {type_name}", *(f"    {line}" for line in setup)]
    pieces: list[str] = []
    for index, (codes, values, string) in enumerate(runs):
        if index == 0:  # from the start: the encapsulation header (0, 1 = little endian, 0, 0)
            fmt, end = _layout(codes, 0)
            namespace["S0"] = struct.Struct("<xBxx" + fmt[1:])
            pieces.append(f"S0.pack({', '.join(['1', *values])})")
            if string is not None:
                body.append(f"    p = {end} + n{string}")  # the offset after the string's NUL
        elif codes:  # after a string: a pad byte for its NUL, then a struct per offset mod 8
            layouts = [_layout(codes, offset) for offset in range(8)]
            namespace[f"S{index}"] = tuple(struct.Struct("<x" + f[1:]) for f, _ in layouts)
            namespace[f"N{index}"] = tuple(end - offset for offset, (_, end) in enumerate(layouts))
            body.append(f"    r{index} = p & 7")
            pieces.append(f"S{index}[r{index}].pack({', '.join(values)})")
            if string is not None:
                body.append(f"    p += N{index}[r{index}] + n{string}")
        else:  # the message ends with a string: its NUL
            pieces.append("b'\\x00'")
        if string is not None:
            pieces.append(f"b{string}")
    body.append(f"    return {' + '.join(pieces)}")
    source = "\n".join(body) + "\n"
    exec(compile(source, f"<rosl serializer {type_name}>", "exec"), namespace)
    serialize: Callable[[Message], bytes] = namespace["serialize"]
    return serialize
