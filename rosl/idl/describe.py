"""Interface text as ``ros2 interface show`` prints it, and ``interface proto``'s prototype.

``show`` prints the definition file line by line; after each field whose type is a message,
that message's definition follows, indented one TAB per level. Comments and blank lines are
kept at the top level, dropped in nested definitions (``all_comments`` keeps them, and
``no_comments`` drops them everywhere).
"""

from __future__ import annotations

from rosl.idl import registry
from rosl.idl.base import ActionType, ServiceType
from rosl.idl.errors import InterfaceError
from rosl.idl.names import TypeName, parse_type_name
from rosl.idl.parser import ActionSpec, ServiceSpec, split_comment


def show(type_name: str, *, all_comments: bool = False, no_comments: bool = False) -> str:
    """Return the text ``ros2 interface show TYPE`` prints (ending in a newline).

    Raises:
        InterfaceError: unknown type or a bad definition.
    """
    name = _interface_name(type_name)
    lines: list[str] = []
    _show(str(name), not no_comments, all_comments, [], lines)
    return "".join(line + "\n" for line in lines)


def _interface_name(type_name: str) -> TypeName:
    name = parse_type_name(type_name)
    if type_name.count("/") == 1 and not registry.exists(str(name)):
        for kind in ("srv", "action"):
            other = TypeName(name.package, kind, name.name)
            if registry.interface_path(other).is_file():
                return other
    return name


def _show(
    type_name: str, comments: bool, nested_comments: bool, parents: list[str], out: list[str]
) -> None:
    if type_name in parents:
        cycle = " -> ".join([*parents[parents.index(type_name) :], type_name])
        raise InterfaceError(f"recursive message definition: {cycle}")
    level = len(parents)
    spec = registry.load_spec(type_name)
    if isinstance(spec, ActionSpec):
        halves = list(spec.parts)
    else:
        halves = [spec.request, spec.response] if isinstance(spec, ServiceSpec) else [spec]
    resolved = {h.type_name: registry.resolve(h) for h in halves}
    lines = spec.text.splitlines()
    # map each line number to the field defined on it (for nesting)
    nested_at: dict[int, str] = {}
    for half in resolved.values():
        for field in half.fields:
            if not field.type.is_primitive:
                nested_at[field.line] = field.type.base
    for number, raw in enumerate(lines, start=1):
        text = raw.rstrip()
        if not comments:
            code, _ = split_comment(text)
            if not code.strip():
                continue  # a blank or comment-only line
            text = code.strip()
        out.append("\t" * level + text if text else "")
        if number in nested_at:
            _show(nested_at[number], nested_comments, nested_comments, [*parents, type_name], out)


def prototype(type_name: str) -> str:
    """Return the YAML of a default instance (the request of a service, an action's goal)."""
    from rosl.idl.yaml_io import message_to_yaml

    cls = registry.get_interface(str(_interface_name(type_name)))
    if issubclass(cls, ActionType):
        message_cls = cls.Goal
    else:
        message_cls = cls.Request if issubclass(cls, ServiceType) else cls
    return message_to_yaml(message_cls())
