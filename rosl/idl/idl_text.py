"""OMG IDL text of our types, as rosidl generates it — for MCAP ``ros2idl`` schemas.

rosbag2 describes service types (``pkg/srv/Name_Event`` in service introspection
recordings) with IDL, since ``.msg`` names cannot say ``srv``. The schema is one section per
type: a line of 80 ``=``, ``IDL: pkg/srv/Name_Event``, then the module text.
"""

from __future__ import annotations

from rosl.idl import registry
from rosl.idl.parser import ArrayKind, Field, FieldType, MessageSpec

DELIMITER = "=" * 80
_PRIMITIVES = {
    "bool": "boolean",
    "byte": "octet",
    "char": "char",
    "float32": "float",
    "float64": "double",
    "string": "string",
}


def _type(ftype: FieldType) -> str:
    if ftype.is_primitive:
        base = _PRIMITIVES.get(ftype.base, ftype.base)
        if ftype.base == "string" and ftype.string_bound:
            base = f"string<{ftype.string_bound}>"
    else:
        base = "::".join(ftype.base.split("/"))
    if ftype.array is ArrayKind.BOUNDED:
        return f"sequence<{base}, {ftype.size}>"
    if ftype.array is ArrayKind.UNBOUNDED:
        return f"sequence<{base}>"
    return base


def _member(field: Field) -> str:
    suffix = f"[{field.type.size}]" if field.type.array is ArrayKind.FIXED else ""
    return f"      {_type(field.type)} {field.name}{suffix};"


def struct_idl(spec: MessageSpec) -> str:
    """The IDL module text of one (resolved) message."""
    package, kind, name = spec.type_name.split("/")
    lines = [f"module {package} {{", f"  module {kind} {{"]
    if spec.constants:
        lines.append(f"    module {name}_Constants {{")
        for constant in spec.constants:
            value = constant.value
            if isinstance(value, bool):
                value = "TRUE" if value else "FALSE"
            elif isinstance(value, str):
                value = '"' + value.replace('"', '\\"') + '"'
            idl_type = _PRIMITIVES.get(constant.type, constant.type)
            lines.append(f"      const {idl_type} {constant.name} = {value};")
        lines.append("    };")
    lines.append(f"    struct {name} {{")
    members = [_member(f) for f in spec.fields] or [
        "      uint8 structure_needs_at_least_one_member;"
    ]
    lines += members
    lines += ["    };", "  };", "};", ""]
    return "\n".join(lines)


def _message_spec(name: str) -> MessageSpec:
    spec = registry.load_spec(name)
    assert isinstance(spec, MessageSpec)  # a recorded type or a field's type: a message
    return registry.resolve(spec)


def full_idl(type_name: str) -> str:
    """A type and every type it uses, as sectioned IDL (rosbag2's ``ros2idl`` layout)."""
    order: list[str] = []

    def visit(name: str) -> None:
        if name in order:
            return
        order.append(name)
        spec = _message_spec(name)
        for field in spec.fields:
            if not field.type.is_primitive:
                visit(field.type.base)

    registry.get_message_class(type_name)
    visit(type_name)
    sections = []
    for name in order:
        spec = _message_spec(name)
        sections.append(f"{DELIMITER}\nIDL: {name}\n{struct_idl(spec)}")
    return "".join(sections)
