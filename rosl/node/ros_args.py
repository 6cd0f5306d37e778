"""``--ros-args`` as rcl reads them: parameters, parameter files, remaps, log levels.

Everything between ``--ros-args`` and ``--`` (or the end) is ROS's; the rest belongs to the
program (``remove_ros_args``). Parameter values are YAML (``-p rate:=1.5`` is a double);
parameter files use ROS 2's layout (``/**`` or a node name, then ``ros__parameters``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rosl.node.errors import RosArgsError
from rosl.node.names import Remap

LEVELS = ("debug", "info", "warn", "error", "fatal", "unset")


@dataclass(slots=True)
class RosArgs:
    """What one ``--ros-args`` command line asked for."""

    params: list[tuple[str | None, str, Any]] = field(default_factory=list)  # (node, name, value)
    params_files: list[Path] = field(default_factory=list)
    remaps: list[Remap] = field(default_factory=list)
    log_levels: dict[str | None, str] = field(default_factory=dict)  # None = default level
    user_args: list[str] = field(default_factory=list)
    enable_rosout: bool = True
    enable_stdout_logs: bool = True

    def node_name(self, default: str) -> str:
        """The node name after ``-r __node:=``/``__name:=`` rules."""
        for rule in self.remaps:
            if rule.source in ("__node", "__name") and rule.node in (None, default):
                return rule.target
        return default

    def namespace(self, default: str | None, node_name: str) -> str | None:
        """The namespace after ``-r __ns:=`` rules."""
        for rule in self.remaps:
            if rule.source == "__ns" and rule.node in (None, node_name):
                return rule.target
        return default

    def overrides(self, node_fqn: str) -> dict[str, Any]:
        """Parameter values for one node: files first (wildcards, then the node), then -p."""
        values: dict[str, Any] = {}
        for path in self.params_files:
            values.update(params_from_file(path, node_fqn))
        name = node_fqn.rsplit("/", 1)[-1]
        for node, key, value in self.params:
            if node is None or node in (name, node_fqn, node_fqn.lstrip("/")):
                values[key] = value
        return values


def split_ros_args(argv: list[str]) -> tuple[list[str], list[str]]:
    """Split argv into (ROS arguments, user arguments)."""
    ros: list[str] = []
    user: list[str] = []
    inside = False
    for arg in argv:
        if arg == "--ros-args":
            inside = True
        elif inside and arg == "--":
            inside = False
        elif inside:
            ros.append(arg)
        else:
            user.append(arg)
    return ros, user


def remove_ros_args(args: list[str]) -> list[str]:
    """Return the arguments that are not ROS arguments (rclpy.utilities.remove_ros_args)."""
    return split_ros_args(list(args))[1]


def parse(argv: list[str] | None) -> RosArgs:
    """Parse a command line's ROS arguments.

    Raises:
        RosArgsError: an unknown flag, a flag without its value, or a malformed rule.
    """
    ros, user = split_ros_args(list(argv or []))
    result = RosArgs(user_args=user)
    items = iter(ros)
    for flag in items:
        if flag in ("-p", "--param"):
            result.params.append(_param(_next(items, flag)))
        elif flag in ("-r", "--remap"):
            result.remaps.append(_remap(_next(items, flag)))
        elif flag == "--params-file":
            path = Path(_next(items, flag)).expanduser()
            if not path.is_file():
                raise RosArgsError(f"--params-file {path}: no such file")
            params_from_file(path, "/")  # validate now, with a clear error
            result.params_files.append(path)
        elif flag == "--log-level":
            _log_level(_next(items, flag), result)
        elif flag in ("-e", "--enclave", "--log-file-name", "--log-config-file"):
            _next(items, flag)
        elif flag in ("--disable-rosout-logs",):
            result.enable_rosout = False
        elif flag in ("--disable-stdout-logs",):
            result.enable_stdout_logs = False
        elif flag.startswith(("--enable-", "--disable-")):
            continue
        else:
            raise RosArgsError(
                f"unknown ROS argument '{flag}' (known: -p/--param, -r/--remap, --params-file, "
                "--log-level, -e/--enclave)"
            )
    return result


def _next(items: Any, flag: str) -> str:
    try:
        return str(next(items))
    except StopIteration:
        raise RosArgsError(f"--ros-args: '{flag}' needs a value after it") from None


def _split_rule(text: str, flag: str) -> tuple[str | None, str, str]:
    if ":=" not in text:
        raise RosArgsError(f"--ros-args {flag} '{text}': expected name:=value")
    left, value = text.split(":=", 1)
    node = None
    if ":" in left:
        node, left = left.split(":", 1)
        if left.startswith("//"):  # rostopic://name has no node prefix
            left, node = f"{node}:{left}", None
    if not left:
        raise RosArgsError(f"--ros-args {flag} '{text}': the name before ':=' is empty")
    return node, left, value


def _param(text: str) -> tuple[str | None, str, Any]:
    node, name, value = _split_rule(text, "-p")
    return node, name, parse_value(value)


def parse_value(text: str) -> Any:
    """Parse a parameter value as YAML (``1`` int, ``1.0`` double, ``true`` bool, lists)."""
    import yaml  # only when a value is given: a node's start-up stays without it

    try:
        value = yaml.safe_load(text) if text.strip() else ""
    except yaml.YAMLError:
        return text
    return "" if value is None else value


def _remap(text: str) -> Remap:
    from rosl.node.errors import InvalidNameError
    from rosl.node.names import validate_namespace, validate_node_name

    node, source, target = _split_rule(text, "-r")
    if not target:
        raise RosArgsError(f"--ros-args -r '{text}': nothing after ':='")
    try:
        if source in ("__node", "__name"):
            validate_node_name(target)
        elif source == "__ns":
            validate_namespace(target if target.startswith("/") else "/" + target)
    except InvalidNameError as err:
        raise RosArgsError(f"--ros-args -r '{text}': {err}") from None
    return Remap(source, target, node)


def _log_level(text: str, result: RosArgs) -> None:
    if ":=" in text:
        name, level = text.split(":=", 1)
    else:
        name, level = None, text
    if level.lower() not in LEVELS:
        raise RosArgsError(f"--log-level '{level}': use one of {', '.join(LEVELS[:-1])}")
    result.log_levels[name] = level.lower()


def params_from_file(
    path: Path, node_fqn: str, *, use_wildcard: bool = True, required: bool = False
) -> dict[str, Any]:
    """Read one node's parameters from a ROS 2 parameter file (wildcard sections first).

    Args:
        path: the file.
        node_fqn: the node's fully qualified name.
        use_wildcard: let ``/**``-style sections apply (``ros2 param load --no-use-wildcard``).
        required: a file with no section for the node is an error (``ros2 param load``).

    Raises:
        RosArgsError: not YAML, not in the ``node: {ros__parameters: {...}}`` layout, or
            (``required``) nothing for the node.
    """
    import yaml

    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    except OSError as err:
        raise RosArgsError(f"{path}: cannot read: {err.strerror}") from None
    except (yaml.YAMLError, UnicodeDecodeError) as err:
        mark = getattr(err, "problem_mark", None)
        where = f"{path}:{mark.line + 1}:{mark.column + 1}" if mark is not None else str(path)
        problem = getattr(err, "problem", None) or "not YAML"
        raise RosArgsError(f"{where}: not a valid YAML parameter file: {problem}") from None
    if not isinstance(data, dict):
        raise RosArgsError(f"{path}: a parameter file maps node names to ros__parameters")
    matches: list[tuple[int, dict[str, Any]]] = []
    for key, section in data.items():
        pattern = str(key) if str(key).startswith("/") else "/" + str(key)
        wildcard = "*" in pattern
        if (wildcard and not use_wildcard) or not _node_matches(pattern, node_fqn):
            continue
        if not isinstance(section, dict) or not isinstance(section.get("ros__parameters"), dict):
            raise RosArgsError(
                f"{path}: section '{key}' needs a 'ros__parameters:' mapping under it"
            )
        matches.append((0 if wildcard else 1, section["ros__parameters"]))
    if required and not matches:
        sections = ", ".join(str(k) for k in data) or "none"
        raise RosArgsError(
            f"Param file {path} does not contain parameters for {node_fqn}, "
            f"only for nodes: {sections}"
        )
    values: dict[str, Any] = {}
    for _, params in sorted(matches, key=lambda m: m[0]):  # the node's own section wins
        values.update(_flatten(params))
    return values


def _node_matches(pattern: str, node_fqn: str) -> bool:
    """Rcl's rule: ``**`` matches any part of a name, ``*`` one token."""
    if "*" not in pattern:
        return pattern == node_fqn
    regex = "".join(
        ".*" if part == "**" else "[^/]*" if part == "*" else re.escape(part)
        for part in re.split(r"(\*\*|\*)", pattern)
    )
    return re.fullmatch(regex, node_fqn) is not None


def _flatten(params: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    flat: dict[str, Any] = {}
    for key, value in params.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(_flatten(value, name + "."))
        else:
            flat[name] = value
    return flat
