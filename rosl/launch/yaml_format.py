"""ROS 2's YAML launch format, for the node/arg/include subset (plus group, let, executable).

::

    launch:
    - arg: {name: topic, default: chatter, description: "..."}
    - node:
        pkg: tutorial_pkg
        exec: my_publisher
        name: publisher_node
        namespace: demo
        output: screen
        param: [{name: rate, value: 2.0}, {from: "$(find-pkg-share p)/params.yaml"}]
        remap: [{from: my_data, to: "$(var topic)"}]
    - include: {file: "$(find-pkg-share p)/launch/other.launch.py", arg: [{name: x, value: "1"}]}

Strings may hold ``$(var N)``, ``$(find-pkg-share P)``, ``$(env N [default])`` and
``$(dirname)``; ``if:``/``unless:`` guard an entry. Errors name the file and line.
"""

from __future__ import annotations

import re
import shlex
from typing import TYPE_CHECKING, Any

import yaml

from rosl.launch import actions, ros_actions
from rosl.launch.description import IfCondition, LaunchDescription, UnlessCondition
from rosl.launch.errors import LaunchError
from rosl.launch.substitutions import (
    EnvironmentVariable,
    FindPackageShare,
    LaunchConfiguration,
    Substitution,
    TextSubstitution,
)

if TYPE_CHECKING:
    from collections.abc import Hashable
    from pathlib import Path

_TOKEN = re.compile(r"\$\(([a-z_-]+)(?:\s+([^)]*))?\)")
LINE = "__line__"
_GUARDS = {"if", "unless"}
_KEYS = {  # the keys rosl reads for each entry; ROS 2 refuses unknown attributes too
    "arg": {"name", "default", "description"},
    "let": {"name", "value"},
    "set_env": {"name", "value"},
    "log": {"message"},
    "push_ros_namespace": {"namespace"},
    "group": {"children", "scoped"},
    "include": {"file", "arg"},
    "executable": {"cmd", "name", "output"},
    "node": {
        "pkg", "exec", "name", "namespace", "output", "param", "remap", "args", "ros_args",
        "respawn",
    },
}  # fmt: skip


class _Loader(yaml.SafeLoader):
    """A safe loader that remembers the line of every mapping."""


def _mapping_with_line(loader: _Loader, node: yaml.MappingNode) -> dict[Hashable, Any]:
    mapping = loader.construct_mapping(node, deep=True)
    mapping[LINE] = node.start_mark.line + 1
    return mapping


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping_with_line)


class _Reader:
    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, line: int, message: str) -> LaunchError:
        return LaunchError(f"{self.path}:{line}: {message}")

    def text(self, value: Any) -> Any:
        """A string with $(...) parts as a list of substitutions (or the plain value)."""
        if isinstance(value, bool):
            return str(value).lower()
        if isinstance(value, (int, float)):
            return str(value)
        if not isinstance(value, str) or "$(" not in value:
            return value
        parts: list[Any] = []
        position = 0
        for match in _TOKEN.finditer(value):
            if match.start() > position:
                parts.append(value[position : match.start()])
            parts.append(self.substitution(match.group(1), (match.group(2) or "").split()))
            position = match.end()
        if position < len(value):
            parts.append(value[position:])
        return parts

    def substitution(self, kind: str, args: list[str]) -> Substitution:
        if kind == "var" and len(args) == 1:
            return LaunchConfiguration(args[0])
        if kind in ("find-pkg-share", "find-pkg-prefix") and len(args) == 1:
            return FindPackageShare(args[0])
        if kind == "env" and args:
            return EnvironmentVariable(
                args[0], default_value=" ".join(args[1:]) if len(args) > 1 else None
            )
        if kind == "dirname":
            return TextSubstitution(text=str(self.path.parent))
        raise LaunchError(
            f"{self.path}: unsupported substitution $({kind} {' '.join(args)}); rosl supports "
            "$(var), $(find-pkg-share), $(env), $(dirname)"
        )

    def condition(self, entry: dict[str, Any]) -> dict[str, Any]:
        if "if" in entry:
            return {"condition": IfCondition(self.text(entry["if"]))}
        if "unless" in entry:
            return {"condition": UnlessCondition(self.text(entry["unless"]))}
        return {}

    def entities(self, items: Any, line: int) -> list[Any]:
        if not isinstance(items, list):
            raise self.fail(
                line, "expected a list of launch entries (- arg:, - node:, - include: ...)"
            )
        out = []
        for item in items:
            if not isinstance(item, dict) or len([k for k in item if k != LINE]) != 1:
                raise self.fail(line, "each launch entry is a single key such as 'node:' or 'arg:'")
            kind = next(k for k in item if k != LINE)
            entry: dict[str, Any] = item[kind] if isinstance(item[kind], dict) else {}
            item_line: int = item.get(LINE, line)
            where: int = entry.get(LINE, item_line)
            method = getattr(self, "entry_" + kind.replace("-", "_"), None)
            if method is None:
                raise self.fail(
                    where,
                    f"unsupported launch entry '{kind}' (rosl reads: arg, let, node, executable, "
                    "include, group, push_ros_namespace, set_env, log)",
                )
            self.keys(entry, _KEYS[kind.replace("-", "_")] | _GUARDS, where, kind)
            out.append(method(item[kind], where))
        return out

    def keys(self, entry: dict[str, Any], allowed: set[str], line: int, what: str) -> None:
        """Refuse a key rosl does not read (a typo would otherwise be ignored)."""
        from rosl.idl.names import did_you_mean

        for key in entry:
            if key != LINE and key not in allowed:
                raise self.fail(
                    line,
                    f"unknown attribute '{key}' in '{what}'{did_you_mean(str(key), allowed)} "
                    f"(rosl reads: {', '.join(sorted(allowed))})",
                )

    def need(self, entry: Any, key: str, line: int) -> Any:
        if not isinstance(entry, dict) or key not in entry:
            raise self.fail(line, f"missing '{key}:'")
        return entry[key]

    def entry_arg(self, entry: dict[str, Any], line: int) -> Any:
        return actions.DeclareLaunchArgument(
            str(self.need(entry, "name", line)),
            default_value=self.text(entry["default"]) if "default" in entry else None,
            description=str(entry.get("description", actions.DEFAULT_DESCRIPTION)),
            **self.condition(entry),
        )

    def entry_let(self, entry: dict[str, Any], line: int) -> Any:
        return actions.SetLaunchConfiguration(
            self.need(entry, "name", line), self.text(self.need(entry, "value", line)),
            **self.condition(entry),
        )  # fmt: skip

    def entry_set_env(self, entry: dict[str, Any], line: int) -> Any:
        return actions.SetEnvironmentVariable(
            self.need(entry, "name", line), self.text(self.need(entry, "value", line))
        )

    def entry_log(self, entry: dict[str, Any], line: int) -> Any:
        return actions.LogInfo(msg=self.text(self.need(entry, "message", line)))

    def entry_push_ros_namespace(self, entry: dict[str, Any], line: int) -> Any:
        return ros_actions.PushRosNamespace(self.text(self.need(entry, "namespace", line)))

    def entry_group(self, entry: Any, line: int) -> Any:
        if isinstance(entry, list):
            return actions.GroupAction(self.entities(entry, line))
        children = self.need(entry, "children", line)
        scoped = str(entry.get("scoped", "true")).lower() != "false"
        return actions.GroupAction(
            self.entities(children, line), scoped=scoped, **self.condition(entry)
        )

    def entry_include(self, entry: dict[str, Any], line: int) -> Any:
        arguments = [
            (str(self.need(a, "name", line)), self.text(self.need(a, "value", line)))
            for a in entry.get("arg", [])
        ]
        return actions.IncludeLaunchDescription(
            actions.PythonLaunchDescriptionSource(self.text(self.need(entry, "file", line))),
            launch_arguments=arguments,
            **self.condition(entry),
        )

    def entry_executable(self, entry: dict[str, Any], line: int) -> Any:
        cmd = self.text(self.need(entry, "cmd", line))
        argv = shlex.split(cmd) if isinstance(cmd, str) else [cmd]
        return actions.ExecuteProcess(
            cmd=argv, name=self.text(entry.get("name")), output=str(entry.get("output", "log")),
            **self.condition(entry),
        )  # fmt: skip

    def entry_node(self, entry: dict[str, Any], line: int) -> Any:
        params: list[Any] = []
        values: dict[str, Any] = {}
        for param in entry.get("param", []):
            if "from" in param:
                params.append(self.text(param["from"]))
            else:
                value = _plain(self.need(param, "value", line))
                if isinstance(value, str) and "$(" in value:
                    value = self.text(value)  # typed by YAML rules once substituted
                values[str(self.need(param, "name", line))] = value
        if values:
            params.insert(0, values)
        remaps = [
            (self.text(self.need(r, "from", line)), self.text(self.need(r, "to", line)))
            for r in entry.get("remap", [])
        ]
        args = entry.get("args")
        ros_args = entry.get("ros_args")
        return ros_actions.Node(
            package=self.text(self.need(entry, "pkg", line)),
            executable=self.text(self.need(entry, "exec", line)),
            name=self.text(entry.get("name")) if "name" in entry else None,
            namespace=self.text(entry.get("namespace")) if "namespace" in entry else None,
            output=str(entry.get("output", "log")),
            parameters=params,
            remappings=remaps,
            arguments=shlex.split(str(args)) if args else [],
            ros_arguments=shlex.split(str(ros_args)) if ros_args else [],
            respawn=bool(entry.get("respawn", False)),
            **self.condition(entry),
        )


def _plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items() if k != LINE}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


def load_yaml(path: Path) -> LaunchDescription:
    """Read a YAML launch file.

    Raises:
        LaunchError: not YAML, no top-level ``launch:`` list, or a bad entry (with its line).
    """
    try:
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=_Loader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        line = mark.line + 1 if mark is not None else 0
        raise LaunchError(
            f"{path}:{line}: not valid YAML: {getattr(err, 'problem', err)}"
        ) from None
    except OSError as err:
        raise LaunchError(f"{path}: cannot read: {err.strerror}") from None
    if not isinstance(data, dict) or "launch" not in data:
        raise LaunchError(
            f"{path}:1: a YAML launch file starts with 'launch:' and a list of entries"
        )
    return LaunchDescription(_Reader(path).entities(data["launch"], data.get(LINE, 1)))
