"""rclpy.parameter's module functions: parameter values between text, messages and Python.

``get_parameter_value`` reads text as ``ros2 param set`` does (YAML: ``1`` an integer,
``[1.0, 2.0]`` a double array, anything else the text itself); ``parameter_value_to_python``
goes the other way; ``parameter_dict_from_yaml_file`` reads a ROS 2 parameter file into
rcl_interfaces/msg/Parameter messages by full name (nested names joined with ``.``).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosl.node.errors import (
    InvalidParameterTypeException,
    InvalidParameterValueException,
    ParameterError,
)
from rosl.node.parameters import Parameter, value_from_msg

if TYPE_CHECKING:
    import os

PARAMETER_SEPARATOR_STRING = "."  # between the parts of a nested name ("pid.kp")


def parameter_value_to_python(parameter_value: Any) -> Any:
    """The Python value of an rcl_interfaces/msg/ParameterValue (None when not set).

    Raises:
        InvalidParameterTypeException: its ``type`` is not a ParameterType.
    """
    try:
        return value_from_msg(parameter_value)[1]
    except ValueError:
        raise InvalidParameterTypeException(
            f"unexpected parameter type {parameter_value.type}"
        ) from None


def get_parameter_value(string_value: str) -> Any:
    """An rcl_interfaces/msg/ParameterValue from text read as YAML (``ros2 param set``'s rule).

    Booleans, integers, doubles and lists of one of them (or of strings) keep their type;
    anything else, mixed lists and text that is not YAML stay the text itself.
    """
    import yaml

    try:
        value = yaml.safe_load(string_value)
    except yaml.YAMLError:
        value = string_value
    if not isinstance(value, (bool, int, float, list)):
        value = string_value
    try:
        return Parameter("", value=value).get_parameter_value()
    except InvalidParameterValueException:
        return Parameter("", value=string_value).get_parameter_value()


def parameter_dict_from_yaml_file(
    parameter_file: str | os.PathLike[str],
    use_wildcard: bool = False,
    target_nodes: list[str] | None = None,
    namespace: str = "",
) -> dict[str, Any]:
    """The parameters of a ROS 2 parameter file, as rcl_interfaces/msg/Parameter by name.

    Args:
        parameter_file: the YAML file (``node: {ros__parameters: {...}}``).
        use_wildcard: include the ``/**`` section (first, so a node's own values win).
        target_nodes: the sections to read (every section but ``/**`` when None).
        namespace: a prefix for every name.

    Raises:
        ParameterError: the file cannot be read, is not YAML, lacks a section asked for, or
            a section has no ``ros__parameters`` mapping (one line naming the file).
    """
    import yaml

    path = Path(parameter_file)
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except OSError as err:
        raise ParameterError(f"{path}: cannot read: {err.strerror}") from None
    except (yaml.YAMLError, UnicodeDecodeError) as err:
        raise ParameterError(f"{path}: not a YAML parameter file ({err})".splitlines()[0]) from None
    if not isinstance(data, dict):
        raise ParameterError(f"{path}: a parameter file maps node names to ros__parameters")
    keys = ["/**"] if use_wildcard and "/**" in data else []
    for node in target_nodes or [k for k in data if k != "/**"]:
        if node not in data:
            raise ParameterError(
                f"Param file {path} does not contain parameters for {node}, only for nodes: "
                + ", ".join(str(k) for k in data)
            )
        keys.append(node)
    if not keys:
        raise ParameterError(f"Param file {path} does not contain selected parameters")
    values: dict[str, Any] = {}
    for key in keys:
        section = data[key]
        if not isinstance(section, dict) or not isinstance(section.get("ros__parameters"), dict):
            raise ParameterError(f"{path}: section '{key}' has no 'ros__parameters:' mapping")
        values.update(section["ros__parameters"])
    return _messages(namespace, values)


def _messages(prefix: str, values: dict[str, Any]) -> dict[str, Any]:
    from rosl.idl.registry import get_message_class

    parameter_class = get_message_class("rcl_interfaces/msg/Parameter")
    found: dict[str, Any] = {}
    for name, value in values.items():
        full = f"{prefix}{name}"
        if isinstance(value, dict):
            found.update(_messages(full + PARAMETER_SEPARATOR_STRING, value))
        else:
            found[full] = parameter_class(name=full, value=get_parameter_value(str(value)))
    return found
