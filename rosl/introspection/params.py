"""``param list/get/set/dump/load/describe/delete`` through the nodes' parameter services."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

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


def _fqn(node: str) -> str:
    return node if node.startswith("/") else "/" + node


def _call(session: Session, node: str, service: str, request_values: dict[str, Any]) -> Any:
    from rosl.idl.registry import get_service_class

    node = _fqn(node)
    session.find_node(node)
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
    from rosl.node.client import ServiceTimeoutError

    try:
        return client.call(request, timeout_sec=TIMEOUT)
    except ServiceTimeoutError:
        raise IntrospectionError(
            f"node {node} did not answer {service} within {TIMEOUT:g} s"
        ) from None


def list_names(session: Session, node: str) -> list[str]:
    """Parameter names of one node, sorted."""
    response = _call(session, node, "list_parameters", {})
    return sorted(response.result.names)


def types_of(session: Session, node: str, names: list[str]) -> list[ParameterType]:
    """The types of some parameters of one node."""
    response = _call(session, node, "get_parameter_types", {"names": names})
    return [ParameterType(int(t)) for t in response.types]


def param_list(
    session: Session,
    node: str | None,
    *,
    filter_regex: str | None = None,
    param_type: bool = False,
    include_hidden: bool = False,
) -> list[str]:
    """The lines ``ros2 param list [NODE]`` prints."""
    from rosl.introspection.session import visible

    nodes = [_fqn(node)] if node else [
        n.fqn for n in session.graph().nodes() if visible(n.fqn, include_hidden)
        and session.graph().has_server(f"{n.fqn}/list_parameters")
    ]  # fmt: skip
    pattern = re.compile(filter_regex) if filter_regex else None
    lines = []
    for fqn in dict.fromkeys(nodes):
        names = [n for n in list_names(session, fqn) if pattern is None or pattern.search(n)]
        kinds = types_of(session, fqn, names) if param_type else []
        lines.append(f"{fqn}:")
        for index, name in enumerate(names):
            suffix = f" (type: {kinds[index].word})" if param_type else ""
            lines.append(f"  {name}{suffix}")
    return lines


def get(session: Session, node: str, name: str, *, hide_type: bool = False) -> str:
    """``ros2 param get``'s line, e.g. ``Double value is: 2.0``."""
    response = _call(session, node, "get_parameters", {"names": [name]})
    kind, value = value_from_msg(response.values[0])
    if kind is ParameterType.NOT_SET:
        raise IntrospectionError(f"Parameter not set: {name} on {_fqn(node)}")
    if kind is ParameterType.BYTE_ARRAY:
        value = list(value)
    text = str(value)
    return text if hide_type else f"{_LABELS[kind]} {text}"


def set_values(
    session: Session, node: str, pairs: list[tuple[str, str]], *, atomic: bool = False
) -> list[str]:
    """Set parameters (values parsed as YAML); return ros2's result lines.

    Raises:
        IntrospectionError: with ros2's "Setting parameter failed: reason" when refused.
    """
    from rosl.node.ros_args import parse_value

    params = [Parameter(name, value=parse_value(text)).to_parameter_msg() for name, text in pairs]
    if atomic:
        response = _call(session, node, "set_parameters_atomically", {"parameters": params})
        results = [response.result]
    else:
        response = _call(session, node, "set_parameters", {"parameters": params})
        results = list(response.results)
    lines = []
    for result in results:
        if not result.successful:
            reason = f": {result.reason}" if result.reason else ""
            raise IntrospectionError(f"Setting parameter failed{reason}")
        lines.append("Set parameter successful" + (f": {result.reason}" if result.reason else ""))
    return lines


def delete(session: Session, node: str, name: str) -> str:
    """Delete (unset) a parameter."""
    param = Parameter(name, ParameterType.NOT_SET).to_parameter_msg()
    response = _call(session, node, "set_parameters", {"parameters": [param]})
    result = response.results[0]
    if not result.successful:
        raise IntrospectionError(f"Deleting parameter failed: {result.reason}")
    return "Deleted parameter successfully"


def dump(session: Session, node: str) -> str:
    """The YAML ``ros2 param dump`` prints: dotted names nested, keys sorted."""
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


def dump_to_dir(session: Session, node: str, directory: Path) -> Path:
    """Write the dump to ``<dir>/<node>.yaml`` (slashes become ``__``)."""
    path = directory / (_fqn(node).lstrip("/").replace("/", "__") + ".yaml")
    try:
        directory.mkdir(parents=True, exist_ok=True)
        path.write_text(dump(session, node), encoding="utf-8")
    except OSError as err:
        raise IntrospectionError(f"cannot write {path}: {err.strerror}") from None
    return path


def load(
    session: Session, node: str, path: Path, *, use_wildcard: bool = True
) -> list[tuple[bool, str]]:
    """Apply a parameter file to a running node; (ok, line) per parameter."""
    from rosl.node.errors import RosArgsError
    from rosl.node.ros_args import params_from_file

    try:
        values = params_from_file(path, _fqn(node))
        if not use_wildcard:
            exact = params_from_file(path, _fqn(node))
            values = {k: v for k, v in exact.items()}
    except RosArgsError as err:
        raise IntrospectionError(str(err)) from None
    if not values:
        raise IntrospectionError(f"{path} has no parameters for {_fqn(node)}")
    params = [Parameter(k, value=v).to_parameter_msg() for k, v in values.items()]
    response = _call(session, node, "set_parameters", {"parameters": params})
    lines = []
    for name, result in zip(values, response.results, strict=True):
        if result.successful:
            lines.append((True, f"Set parameter {name} successful"))
        else:
            lines.append((False, f"Set parameter {name} failed: {result.reason}"))
    return lines


def describe(session: Session, node: str, names: list[str]) -> list[str]:
    """``ros2 param describe``'s lines."""
    response = _call(session, node, "describe_parameters", {"names": names})
    if not response.descriptors:
        raise IntrospectionError(f"Parameter not declared: {', '.join(names)} on {_fqn(node)}")
    lines = []
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
        for rng in descriptor.floating_point_range or descriptor.integer_range:
            lines += [f"    Min value: {rng.from_value}", f"    Max value: {rng.to_value}"]
            if rng.step:
                lines.append(f"    Step: {rng.step}")
        if descriptor.additional_constraints:
            lines.append(f"    Additional constraints: {descriptor.additional_constraints}")
    return lines
