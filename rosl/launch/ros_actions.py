"""launch_ros's actions: Node, PushRosNamespace, SetParameter, SetRemap (and ParameterValue).

Components (ComposableNodeContainer, LoadComposableNodes) are refused with one line naming
the launch file's line: components are C++ plugins. LifecycleNode lives in launch/lifecycle.py.

A Node becomes ``<executable> [arguments] --ros-args -r __node:=NAME -r __ns:=NS
--params-file FILE -r from:=to ...`` — the same ``--ros-args`` a user could type. Parameter
dicts are written to a YAML file in the launch's log folder, as ROS 2 does.
"""

from __future__ import annotations

import traceback
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosl.launch.actions import ExecuteProcess, TimerAction
from rosl.launch.description import Action
from rosl.launch.errors import LaunchError
from rosl.launch.substitutions import (
    SomeSubstitutions,
    Substitution,
    describe,
    perform,
    resolve_value,
)

if TYPE_CHECKING:
    from rosl.launch.context import LaunchContext


class ParameterValue:
    """A parameter value given explicitly, optionally with its type (launch_ros's class).

    Without ``value_type`` a substituted value is read by YAML rules, as any other; with it
    (``str``, ``int``, ``float``, ``bool`` or a list of one of them) it is converted to it.
    """

    def __init__(self, value: Any, *, value_type: Any = None) -> None:
        self.value = value
        self.value_type = value_type


class ParameterFile:
    """A parameter file given to a Node (launch_ros.descriptions.ParameterFile).

    With ``allow_substs`` the file's ``$(...)`` substitutions (``$(var x)``, ``$(env X)``, ...)
    are performed first, and the node gets the substituted copy.
    """

    def __init__(
        self, param_file: SomeSubstitutions, *, allow_substs: bool | SomeSubstitutions = False
    ) -> None:
        self.param_file = param_file
        self.allow_substs = allow_substs

    def substituted(self, context: LaunchContext, path: Path, label: str) -> Path:
        """The file to hand to the node: ``path``, or its substituted copy.

        Raises:
            LaunchError: a substitution in the file cannot be read or performed.
        """
        allow = self.allow_substs
        if not isinstance(allow, bool):
            allow = perform(context, allow).strip().lower() in ("true", "1", "yes", "on")
        if not allow:
            return path
        from rosl.launch.substitution_text import SubstitutionSyntaxError, parse_substitution

        try:
            text = perform(context, parse_substitution(path.read_text(encoding="utf-8"), path=path))
        except SubstitutionSyntaxError as err:
            raise LaunchError(f"{path}: bad substitution: {err}") from None
        except (OSError, UnicodeDecodeError) as err:
            raise LaunchError(f"{path}: cannot read: {err}") from None
        if context.supervisor is None:
            return path
        return context.supervisor.parameter_files.write_text(label, text)


def yaml_typed(text: str) -> Any:
    """``'0.9'`` -> 0.9, ``'true'`` -> True, ``'[1, 2]'`` -> [1, 2]; other text stays text."""
    import yaml

    try:
        loaded = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    if isinstance(loaded, (bool, int, float, str)):
        return loaded
    if (
        isinstance(loaded, list)
        and loaded
        and len({type(v) for v in loaded}) == 1
        and isinstance(loaded[0], (bool, int, float, str))
    ):
        return loaded
    return text


def _substituted(value: Any) -> bool:
    if isinstance(value, Substitution):
        return True
    return (
        isinstance(value, (list, tuple))
        and bool(value)
        and all(isinstance(v, (str, Substitution)) for v in value)
        and any(isinstance(v, Substitution) for v in value)
    )


def parameter_value(context: LaunchContext, value: Any) -> Any:
    """A parameter's value as launch_ros evaluates it: substitutions by YAML rules."""
    if isinstance(value, ParameterValue):
        resolved = parameter_value(context, value.value)
        kind = value.value_type
        if kind is None:
            return resolved
        try:
            if kind is str:
                return perform(context, value.value) if _substituted(value.value) else str(resolved)
            if kind is bool and isinstance(resolved, str):
                return yaml_typed(resolved) is True
            return kind(resolved)
        except (TypeError, ValueError):
            raise LaunchError(
                f"parameter value {resolved!r} is not a {getattr(kind, '__name__', kind)}"
            ) from None
    if _substituted(value):
        return yaml_typed(perform(context, value))
    if isinstance(value, dict):
        return {perform(context, k): parameter_value(context, v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [parameter_value(context, v) for v in value]
    return resolve_value(context, value)


_FOXY_NAMES = {"node_executable": "executable", "node_name": "name",
               "node_namespace": "namespace"}  # fmt: skip


class Node(ExecuteProcess):
    """Start a package's executable as a ROS node (launch_ros.actions.Node)."""

    def __init__(
        self,
        *,
        executable: SomeSubstitutions = None,
        package: SomeSubstitutions = None,
        name: SomeSubstitutions = None,
        namespace: SomeSubstitutions = None,
        exec_name: SomeSubstitutions = None,
        parameters: list[Any] | None = None,
        remappings: list[tuple[SomeSubstitutions, SomeSubstitutions]] | None = None,
        ros_arguments: list[SomeSubstitutions] | None = None,
        arguments: list[SomeSubstitutions] | None = None,
        **kwargs: Any,
    ) -> None:
        old = sorted(k for k in kwargs if k in _FOXY_NAMES)
        if old:
            spelled = ", ".join(f"{k}= is now {_FOXY_NAMES[k]}=" for k in old)
            raise LaunchError(
                f"Node(): {spelled} (ROS 2 Dashing/Foxy's spelling, gone since Galactic)"
            )
        if executable is None:
            raise LaunchError("Node() needs executable= (and package=)")
        super().__init__(cmd=[], **kwargs)
        self.package = package
        self.executable = executable
        self.node_name = name
        self.node_namespace = namespace
        self.exec_name = exec_name
        self.parameters = list(parameters or [])
        self.remappings = list(remappings or [])
        self.ros_arguments = list(ros_arguments or [])
        self.arguments = list(arguments or [])

    def _namespace(self, context: LaunchContext) -> str:
        scoped = context.scope.namespace
        own = perform(context, self.node_namespace) if self.node_namespace is not None else ""
        if own.startswith("/"):
            return own.rstrip("/") or "/"
        joined = "/".join(part for part in (scoped.strip("/"), own.strip("/")) if part)
        return "/" + joined if joined else ""

    def _parameter_arguments(self, context: LaunchContext) -> tuple[list[str], dict[str, Any]]:
        """``--params-file`` arguments in the order the parameters were given (later wins).

        Inline values (and SetParameter's, first) go to a file the launcher writes, one per run
        of consecutive dicts, in their place among the user's files. ``--print`` shows them as
        ``-p`` (no file is written for a dry run).
        """
        values: dict[str, Any] = {}  # every inline value (what --print and the details show)
        steps: list[dict[str, Any] | str] = []  # inline groups and user files, in order
        group: dict[str, Any] = {}
        for entry in [*_scoped_parameters(context), *self.parameters]:
            if isinstance(entry, dict):
                for key, value in entry.items():
                    group[perform(context, key)] = parameter_value(context, value)
            elif isinstance(entry, (str, Path, Substitution, list, tuple, ParameterFile)):
                path = _parameter_file(context, entry)
                if not path.is_file():
                    raise LaunchError(
                        f"parameter file {path} (for {self._label(context)}) does not exist"
                    )
                if isinstance(entry, ParameterFile):
                    path = entry.substituted(context, path, self._label(context))
                if group:
                    steps.append(group)
                    group = {}
                steps.append(str(path))
            else:
                raise LaunchError(
                    f"parameters of {self._label(context)} must be dicts or YAML file paths, "
                    f"not {type(entry).__name__}"
                )
        if group:
            steps.append(group)
        for step in steps:
            if isinstance(step, dict):
                values.update(step)
        supervisor = context.supervisor
        args: list[str] = []
        if supervisor is not None and supervisor.dry_run:
            for key, value in values.items():  # --print: a command line that runs as printed
                args += ["-p", f"{key}:={_yaml_value(value)}"]
            for step in steps:
                if isinstance(step, str):
                    args += ["--params-file", step]
        elif supervisor is not None:
            for step in steps:
                if isinstance(step, dict):
                    step = str(supervisor.parameter_files.write(self._label(context), step))
                args += ["--params-file", step]
        return args, values

    def _label(self, context: LaunchContext) -> str:
        if self.node_name is not None:
            return perform(context, self.node_name)
        return perform(context, self.executable)

    def command(self, context: LaunchContext) -> list[str]:
        """The command line of the node, with its ``--ros-args``."""
        from rosl.pkg.errors import PackageError
        from rosl.pkg.executables import command_line, find_executable

        if self.package is None:
            raise LaunchError(
                f"Node(executable='{perform(context, self.executable)}') needs package="
            )
        package = perform(context, self.package)
        executable = perform(context, self.executable)
        try:
            found = find_executable(package, executable)
        except PackageError as err:
            raise LaunchError(str(err)) from None
        ros: list[str] = []
        if self.node_name is not None:
            ros += ["-r", f"__node:={perform(context, self.node_name)}"]
        namespace = self._namespace(context)
        if namespace:
            ros += ["-r", f"__ns:={namespace}"]
        params, _ = self._parameter_arguments(context)
        ros += params
        for source, target in [*context.scope.remappings, *self.remappings]:
            ros += ["-r", f"{perform(context, source)}:={perform(context, target)}"]
        ros += [perform(context, a) for a in self.ros_arguments]
        user = [perform(context, a) for a in self.arguments]
        return command_line(found, [*user, *(["--ros-args", *ros] if ros else [])])

    def base_name(self, context: LaunchContext, argv: list[str]) -> str:
        """``[executable-N]`` as ROS 2 names a node's output."""
        if self.exec_name is not None:
            return perform(context, self.exec_name)
        return perform(context, self.executable)

    def details(self, context: LaunchContext) -> dict[str, Any]:
        """Package, executable, name, namespace, parameters and remaps, for ``--print``."""
        _, values = self._parameter_arguments_preview(context)
        return {
            "package": perform(context, self.package),
            "executable": perform(context, self.executable),
            "name": perform(context, self.node_name) if self.node_name is not None else None,
            "namespace": self._namespace(context) or "/",
            "parameters": values,
            "remappings": [
                (perform(context, s), perform(context, t))
                for s, t in [*context.scope.remappings, *self.remappings]
            ],
        }

    def _parameter_arguments_preview(
        self, context: LaunchContext
    ) -> tuple[list[str], dict[str, Any]]:
        values: dict[str, Any] = {}
        for entry in [*_scoped_parameters(context), *self.parameters]:
            if isinstance(entry, dict):
                values.update(
                    {perform(context, k): parameter_value(context, v) for k, v in entry.items()}
                )
            else:
                values[f"(file) {_parameter_file(context, entry)}"] = "..."
        return [], values


def _scoped_parameters(context: LaunchContext) -> list[Any]:
    """SetParameter's values (as one-entry dicts) and SetParametersFromFile's files, in order."""
    return [
        entry if isinstance(entry, ParameterFile) else {entry[0]: entry[1]}
        for entry in context.scope.parameters
    ]


def _parameter_file(context: LaunchContext, entry: Any) -> Path:
    if isinstance(entry, ParameterFile):
        entry = entry.param_file
    return entry if isinstance(entry, Path) else Path(perform(context, entry))


class PushRosNamespace(Action):
    """Put the nodes after it (in this scope) under a namespace."""

    def __init__(self, namespace: SomeSubstitutions, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.namespace = namespace

    def execute(self, context: LaunchContext) -> None:
        """Push the namespace on the current scope."""
        context.push_namespace(perform(context, self.namespace))


class SetParameter(Action):
    """Give a parameter to every node started after it (in this scope)."""

    def __init__(self, name: SomeSubstitutions, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.name = name
        self.value = value

    def execute(self, context: LaunchContext) -> None:
        """Record it on the current scope."""
        context.scope.parameters.append((self.name, self.value))


class SetParametersFromFile(Action):
    """Give a parameter file to every node started after it (in this scope), before its own."""

    def __init__(self, filename: SomeSubstitutions, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.filename = filename

    def execute(self, context: LaunchContext) -> None:
        """Record it on the current scope."""
        context.scope.parameters.append(ParameterFile(perform(context, self.filename)))


class SetUseSimTime(SetParameter):
    """``use_sim_time`` for every node started after it (in this scope)."""

    def __init__(self, value: Any, **kwargs: Any) -> None:
        super().__init__("use_sim_time", value, **kwargs)


class RosTimer(TimerAction):
    """Run actions after a period (launch_ros.actions.RosTimer; rosl times it by the wall clock)."""


class SetRemap(Action):
    """Remap a name for every node started after it (in this scope)."""

    def __init__(self, src: SomeSubstitutions, dst: SomeSubstitutions, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.src = src
        self.dst = dst

    def execute(self, context: LaunchContext) -> None:
        """Record it on the current scope."""
        context.scope.remappings.append((self.src, self.dst))


class ComposableNode:
    """A C++ component to load into a container (launch_ros.descriptions.ComposableNode).

    Kept as given: the container or LoadComposableNodes that receives it refuses to run.
    """

    def __init__(
        self,
        *,
        package: SomeSubstitutions,
        plugin: SomeSubstitutions,
        name: SomeSubstitutions = None,
        namespace: SomeSubstitutions = None,
        **kwargs: Any,
    ) -> None:
        self.package = package
        self.plugin = plugin
        self.name = name
        self.namespace = namespace
        self.options = kwargs


def _user_site() -> str:
    """``file:line: `` of the innermost caller outside rosl (the launch file's line)."""
    rosl_dir = Path(__file__).resolve().parents[1]
    for frame in reversed(traceback.extract_stack()):
        path = Path(frame.filename)
        if path.is_file() and rosl_dir not in path.resolve().parents:
            return f"{frame.filename}:{frame.lineno}: "
    return ""


def _shown(value: SomeSubstitutions) -> str:
    return value if isinstance(value, str) else describe(value)


def _refuse_components(what: str, descriptions: Any) -> LaunchError:
    plugins = [
        _shown(d.plugin) if isinstance(d, ComposableNode) else type(d).__name__
        for d in (descriptions or [])
    ]
    listed = f": {', '.join(plugins)}" if plugins else ""
    return LaunchError(
        f"{_user_site()}'launch_ros.actions.{what}' is not supported: it runs C++ components, "
        f"which rosl cannot{listed} (start each as a Node of a Python package instead)"
    )


class ComposableNodeContainer(Action):
    """Refused when created: a component container loads C++ plugins."""

    def __init__(self, *, composable_node_descriptions: Any = None, **kwargs: Any) -> None:
        raise _refuse_components("ComposableNodeContainer", composable_node_descriptions)


class LoadComposableNodes(Action):
    """Refused when created: it loads C++ plugins into a container."""

    def __init__(self, *, composable_node_descriptions: Any = None, **kwargs: Any) -> None:
        raise _refuse_components("LoadComposableNodes", composable_node_descriptions)


def _yaml_value(value: Any) -> str:
    """A parameter value as ``-p name:=VALUE`` text that YAML reads back as the same value."""
    import yaml

    return (
        str(yaml.safe_dump(value, default_flow_style=True, width=1 << 30))
        .strip()
        .removesuffix("\n...")
        .strip()
    )
