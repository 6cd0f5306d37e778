"""``param list/get/set/dump/load/describe/delete`` through the nodes' parameter services."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

from rosl.errors import RoslError
from rosl.idl.names import did_you_mean
from rosl.introspection.errors import IntrospectionError
from rosl.node.parameters import Parameter, ParameterType, value_from_msg

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.introspection.session import Session

TIMEOUT = 5.0
_LABELS = {
    ParameterType.BOOL: "Boolean value is:",
    ParameterType.INTEGER: "Integer value is:",
    ParameterType.DOUBLE: "Double value is:",
    ParameterType.STRING: "String value is:",
    ParameterType.BYTE_ARRAY: "Byte values are:",
    ParameterType.BOOL_ARRAY: "Boolean values are:",
    ParameterType.INTEGER_ARRAY: "Integer values are:",
    ParameterType.DOUBLE_ARRAY: "Double values are:",
    ParameterType.STRING_ARRAY: "String values are:",
}
Outcome = tuple[bool, str]  # (succeeded, ros2's line: stdout when it did, stderr when not)


NODE_NOT_FOUND = "Node not found"


def _fqn(node: str) -> str:
    return node if node.startswith("/") else "/" + node


def require_node(session: Session, node: str, *, include_hidden: bool = False) -> None:
    """Check, before anything else, that ``node`` runs, as every ``ros2 param`` verb does.

    Raises:
        IntrospectionError: ros2's "Node not found" (with the closest name, if any); a hidden
            node counts only with ``include_hidden`` (``--include-hidden-nodes``).
    """
    session.find_node(_fqn(node), visible_only=not include_hidden, missing=NODE_NOT_FOUND)


def _call(session: Session, node: str, service: str, request_values: dict[str, Any]) -> Any:
    from rosl.idl.registry import get_service_class
    from rosl.node.client import ServiceTimeoutError

    node = _fqn(node)
    session.find_node(node, missing=NODE_NOT_FOUND)
    srv = get_service_class(
        f"rcl_interfaces/srv/{''.join(p.capitalize() for p in service.split('_'))}"
    )
    client = session.node().create_client(srv, f"{node}/{service}")
    if not client.wait_for_service(timeout_sec=TIMEOUT):
        raise IntrospectionError(
            f"Wait for service timed out waiting for parameter services for node {node}"
        )
    request = srv.Request()
    for key, value in request_values.items():
        setattr(request, key, value)
    try:
        return client.call(request, timeout_sec=TIMEOUT)
    except ServiceTimeoutError:
        raise IntrospectionError(
            f"node {node} did not answer {service} within {TIMEOUT:g} s"
        ) from None


def list_names(session: Session, node: str, prefixes: list[str] | None = None) -> list[str]:
    """Parameter names of one node (only under ``prefixes`` when given), sorted."""
    response = _call(session, node, "list_parameters", {"prefixes": list(prefixes or [])})
    return sorted(response.result.names)


def types_of(session: Session, node: str, names: list[str]) -> list[ParameterType]:
    """The types of some parameters of one node."""
    response = _call(session, node, "get_parameter_types", {"names": names})
    return [ParameterType(int(t)) for t in response.types]


def _unknown(session: Session, node: str, names: list[str]) -> str:
    """``'a' on /node (did you mean 'b'?)`` for parameters the node does not have."""
    return f"{', '.join(names)} on {_fqn(node)}{_closest(session, node, names)}"


def _closest(session: Session, node: str, names: list[str]) -> str:
    """`` (did you mean 'b'?)`` for one parameter the node does not have, else nothing."""
    known = set(list_names(session, node))
    return did_you_mean(names[0], known) if len(names) == 1 else ""


def _humble_text(kind: ParameterType, value: Any) -> str:
    """A value as ``ros2 param get`` (Humble) prints the message field holding it."""
    import array

    if kind is ParameterType.INTEGER_ARRAY:
        return repr(array.array("q", value))  # rclpy's int64[] field
    if kind is ParameterType.DOUBLE_ARRAY:
        return repr(array.array("d", value))  # rclpy's float64[] field
    if kind is ParameterType.BYTE_ARRAY:
        return str([bytes([b]) for b in value])  # rclpy's byte[] field: one bytes each
    return str(value)


def param_list(
    session: Session,
    node: str | None,
    *,
    filter_regex: str | None = None,
    prefixes: list[str] | None = None,
    param_type: bool = False,
    include_hidden: bool = False,
) -> list[str]:
    """The lines ``ros2 param list [NODE]`` prints.

    As ros2 does: a ``/node:`` header only when no NODE was named, and only for nodes with
    something to list; ``--filter`` keeps names the regex matches at their start (``re.match``).
    """
    from rosl.introspection.session import visible

    try:
        pattern = re.compile(filter_regex) if filter_regex is not None else None
    except re.error as err:
        raise IntrospectionError(
            f"bad --filter regular expression '{filter_regex}': {err}"
        ) from None
    if node:
        nodes = [_fqn(node)]
    else:
        graph = session.graph()
        found = {
            n.fqn: (n.name, n.namespace) for n in graph.nodes()
            if visible(n.fqn, include_hidden) and graph.has_server(f"{n.fqn}/list_parameters")
        }  # fmt: skip
        nodes = sorted(found, key=lambda fqn: found[fqn])  # ros2 sorts by (name, namespace)
    lines: list[str] = []
    for fqn in nodes:
        names = list_names(session, fqn, prefixes)
        names = [n for n in names if pattern is None or pattern.match(n)]
        if not names:
            continue
        if not node:
            lines.append(f"{fqn}:")
        kinds = types_of(session, fqn, names) if param_type else []
        for index, name in enumerate(names):
            lines.append(f"  {name} (type: {kinds[index].word})" if param_type else f"  {name}")
    return lines


def get(session: Session, node: str, name: str, *, hide_type: bool = False) -> str:
    """``ros2 param get``'s line, e.g. ``Double value is: 2.0``."""
    response = _call(session, node, "get_parameters", {"names": [name]})
    value: Any  # value_from_msg's Python value, None when not set
    kind, value = (
        value_from_msg(response.values[0]) if response.values else (ParameterType.NOT_SET, None)
    )
    if kind is ParameterType.NOT_SET:
        raise IntrospectionError("Parameter not set" + _closest(session, node, [name]))
    text = _humble_text(kind, value)
    return text if hide_type else f"{_LABELS[kind]} {text}"


def set_values(
    session: Session, node: str, pairs: list[tuple[str, str]], *, atomic: bool = False
) -> list[Outcome]:
    """Set parameters (values parsed as YAML); one outcome per ros2 result line.

    With one parameter the lines are ros2's ``Set parameter successful`` / ``Setting parameter
    failed: <reason>``; with several each is prefixed ``<name>: ``; ``--atomic`` gives one
    ``Set parameters atomically successful`` / ``Setting parameters atomically failed`` line.
    """
    params = [Parameter(name, value=_value(text)).to_parameter_msg() for name, text in pairs]
    if atomic:
        response = _call(session, node, "set_parameters_atomically", {"parameters": params})
        result = response.result
        word = "Set parameters atomically successful" if result.successful else (
            "Setting parameters atomically failed"
        )  # fmt: skip
        return [(bool(result.successful), word + (f": {result.reason}" if result.reason else ""))]
    response = _call(session, node, "set_parameters", {"parameters": params})
    outcomes: list[Outcome] = []
    declared: set[str] | None = None
    for (name, _), result in zip(pairs, response.results, strict=True):
        word = "Set parameter successful" if result.successful else "Setting parameter failed"
        line = word + (f": {result.reason}" if result.reason else "")
        if not result.successful:
            declared = set(list_names(session, node)) if declared is None else declared
            line += "" if name in declared else did_you_mean(name, declared)
        outcomes.append((bool(result.successful), f"{name}: {line}" if len(pairs) > 1 else line))
    return outcomes


def _value(text: str) -> Any:
    """A command-line value as ros2 reads it: YAML, else the text itself as a string."""
    from rosl.node.ros_args import parse_value

    value = parse_value(text)
    try:
        ParameterType.from_parameter_value(value)
    except RoslError:
        return text  # a mapping, a mixed list...: ros2 sets the string
    return value


def delete(session: Session, node: str, name: str) -> str:
    """Delete (unset) a parameter; ros2's ``Deleted parameter successfully``.

    Raises:
        IntrospectionError: ros2's ``Deleting parameter failed: <reason>``.
    """
    param = Parameter(name, ParameterType.NOT_SET).to_parameter_msg()
    response = _call(session, node, "set_parameters", {"parameters": [param]})
    result = response.results[0]
    reason = f": {result.reason}" if result.reason else ""
    if not result.successful:
        known = set(list_names(session, node))
        hint = "" if name in known else did_you_mean(name, known)
        raise IntrospectionError(f"Deleting parameter failed{reason}{hint}")
    return "Deleted parameter successfully" + reason


def dump(session: Session, node: str) -> str:
    """The YAML ``ros2 param dump`` writes: dotted names nested, keys sorted.

    ros2 prints it with ``print``, so on stdout a blank line follows it.
    """
    import yaml

    names = list_names(session, node)
    response = _call(session, node, "get_parameters", {"names": names})
    tree: dict[str, Any] = {}
    for name, value_msg in zip(names, response.values, strict=True):
        kind, value = value_from_msg(value_msg)
        if kind is ParameterType.BYTE_ARRAY:
            value = list(value)
        cursor = tree
        parts = name.split(".")
        for part in parts[:-1]:
            cursor = cursor.setdefault(part, {})
        cursor[parts[-1]] = value
    return yaml.dump({_fqn(node): {"ros__parameters": tree}}, default_flow_style=False)


def dump_to_dir(session: Session, node: str, directory: str) -> str:
    """Write the dump to ``<dir>/<node>.yaml`` (slashes become ``__``); return that path.

    Raises:
        IntrospectionError: ros2's "'<dir>' is not a valid directory." for a missing folder
            (checked after the node, as ros2 does), or the file cannot be written.
    """
    import os

    if not os.path.isdir(directory):
        raise IntrospectionError(f"'{directory}' is not a valid directory.")
    path = os.path.join(directory, _fqn(node).lstrip("/").replace("/", "__") + ".yaml")
    text = dump(session, node)
    try:
        with open(path, "w", encoding="utf-8") as handle:
            handle.write(text)
    except OSError as err:
        raise IntrospectionError(f"cannot write {path}: {err.strerror}") from None
    return path


def file_values(path: Path, node: str, *, use_wildcard: bool = True) -> dict[str, Any]:
    """One node's parameters from a parameter file, as ``ros2 param load`` picks them.

    The node's own section (``/node`` or ``node``) always applies; with ``use_wildcard`` the
    wildcard sections (``/**``, ``/**/node``...) apply first, so the node's own values win.

    Raises:
        IntrospectionError: the file is not YAML, not a parameter file, or has nothing for node.
    """
    from rosl.node.errors import RosArgsError
    from rosl.node.ros_args import params_from_file

    try:
        return params_from_file(path, _fqn(node), use_wildcard=use_wildcard, required=True)
    except RosArgsError as err:
        raise IntrospectionError(str(err)) from None


def load(session: Session, node: str, path: Path, *, use_wildcard: bool = True) -> list[Outcome]:
    """Apply a parameter file to a running node; ros2's line per parameter."""
    require_node(session, node, include_hidden=True)  # as ros2: the node first, then the file
    values = file_values(path, node, use_wildcard=use_wildcard)
    try:
        params = [Parameter(k, value=v).to_parameter_msg() for k, v in values.items()]
    except RoslError as err:
        raise IntrospectionError(f"{path}: {err}") from None
    response = _call(session, node, "set_parameters", {"parameters": params})
    outcomes: list[Outcome] = []
    for name, result in zip(values, response.results, strict=True):
        reason = f": {result.reason}" if result.reason else ""
        word = "successful" if result.successful else "failed"
        outcomes.append((bool(result.successful), f"Set parameter {name} {word}{reason}"))
    return outcomes


def describe(session: Session, node: str, names: list[str]) -> list[str]:
    """``ros2 param describe``'s lines."""
    response = _call(session, node, "describe_parameters", {"names": names})
    missing = [n for n in names if n not in {d.name for d in response.descriptors}]
    if missing:
        raise IntrospectionError(f"Parameter not declared: {_unknown(session, node, missing)}")
    lines: list[str] = []
    for descriptor in response.descriptors:
        lines += [
            f"Parameter name: {descriptor.name}",
            f"  Type: {ParameterType(descriptor.type).word}",
        ]
        if descriptor.description:
            lines.append(f"  Description: {descriptor.description}")
        lines.append("  Constraints:")
        if descriptor.read_only:
            lines.append("    Read only: true")
        ranges = [*descriptor.floating_point_range, *descriptor.integer_range]
        if ranges:
            lines += [
                f"    Min value: {ranges[0].from_value}",
                f"    Max value: {ranges[0].to_value}",
            ]
            if ranges[0].step:
                lines.append(f"    Step: {ranges[0].step}")
        if descriptor.additional_constraints:
            lines.append(f"    Additional constraints: {descriptor.additional_constraints}")
    return lines
