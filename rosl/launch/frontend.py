"""What XML and YAML launch files share: ``$(...)`` strings and the tags that become actions.

A format reads its file into :class:`Entity` objects (``xml_format``, ``yaml_format``); this
module turns them into the actions a Python launch file would build, with the tag, attribute
and substitution names of ROS 2's ``launch.frontend`` and of the ``parse`` methods of launch's
and launch_ros's actions. Every mistake is ``file:line: what is wrong``, and an action that
fails while it runs names the line of its tag as well.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosl.launch import actions, ros_actions
from rosl.launch.description import IfCondition, LaunchDescription, UnlessCondition
from rosl.launch.errors import LaunchError
from rosl.launch.substitution_text import SubstitutionSyntaxError, joined, parse_substitution

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

# --- entities ------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Tag:
    """What a tag may hold: attributes, nested entities, and (for groups) child actions."""

    attributes: frozenset[str]
    nested: frozenset[str] = frozenset()
    children: bool = False


def _tag(attributes: str, nested: str = "", *, children: bool = False) -> Tag:
    return Tag(frozenset(attributes.split()), frozenset(nested.split()), children)


_HINTS = {  # ROS 1 habits
    ("group", "ns"): ": ROS 2 puts a <push-ros-namespace namespace=...> first in the group",
    ("node", "type"): ": ROS 2 names the executable with 'exec'",
    ("node", "ns"): ": ROS 2 calls it 'namespace'",
}


class Entity:
    """One tag of a launch file (an XML element, a YAML mapping), as the builders read it."""

    noun = "tag"

    def __init__(self, path: Path, line: int, kind: str) -> None:
        self.path = path
        self.line = line
        self.kind = kind

    @property
    def label(self) -> str:
        """How messages name this tag."""
        return f"'{self.kind}'"

    def fail(self, message: str) -> LaunchError:
        """An error naming this tag's file and line."""
        return LaunchError(f"{self.path}:{self.line}: {message}")

    def value(self, name: str) -> Any:
        """The raw value of an attribute (None when absent)."""
        raise NotImplementedError

    def nested(self, name: str) -> list[Entity]:
        """The nested entities called ``name`` (``<param>`` in a node, ``param:`` in YAML)."""
        raise NotImplementedError

    def actions(self) -> list[Entity]:
        """The child actions (of ``<launch>``, ``<group>``, ``<timer>``)."""
        raise NotImplementedError

    def check(self, tag: Tag, guarded: bool) -> None:
        """Refuse an attribute or nested entity ``tag`` does not have (a typo is not ignored)."""
        raise NotImplementedError

    def typed(self, text: str) -> Any:
        """A parameter value written as text, typed (XML: by YAML rules; YAML: as it is)."""
        return text

    def unknown(self, name: str, known: frozenset[str] | set[str], what: str) -> LaunchError:
        """``unknown attribute 'x' in <node> (did you mean 'y'?) (rosl reads: ...)``."""
        from rosl.idl.names import did_you_mean

        hint = _HINTS.get((self.kind, name)) or (
            f"{did_you_mean(name, known)} (rosl reads: {', '.join(sorted(known)) or 'none'})"
        )
        return self.fail(f"unknown {what} '{name}' in {self.label}{hint}")


def _text(entity: Entity, name: str, *, required: bool = False) -> Any:
    """An attribute as text with substitutions (None when absent and not required)."""
    value = entity.value(name)
    if value is None:
        if required:
            raise entity.fail(f"{entity.label} needs the attribute '{name}'")
        return None
    return _substituted(entity, _scalar(entity, name, value))


def _scalar(entity: Entity, name: str, value: Any) -> str:
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, (int, float, str)):
        return str(value)
    raise entity.fail(f"attribute '{name}' of {entity.label} must be one value, not {value!r}")


def _substituted(entity: Entity, text: str) -> Any:
    try:
        return parse_substitution(text, path=entity.path)
    except SubstitutionSyntaxError as err:
        raise entity.fail(f"bad substitution in '{text}': {err}") from None


def _plain(entity: Entity, name: str, *, required: bool = False) -> str | None:
    """An attribute read literally (escapes only), as launch reads names and descriptions."""
    value = entity.value(name)
    if value is None:
        if required:
            raise entity.fail(f"{entity.label} needs the attribute '{name}'")
        return None
    return re.sub(r"\\(.)", r"\1", _scalar(entity, name, value))


# launch types a boolean attribute by YAML rules: YAML 1.1's words, as PyYAML reads them
TRUE_WORDS = ("true", "yes", "on")
FALSE_WORDS = ("false", "no", "off")


def _flag(entity: Entity, name: str, *, substitutions: bool = False) -> Any:
    """A boolean attribute (with ``substitutions``, a ``$(...)`` resolved at run time).

    ``true``/``false`` and YAML's ``yes``/``no``/``on``/``off``, as launch's frontend reads them.
    """
    value = entity.value(name)
    if value is None or isinstance(value, bool):
        return value
    text = _scalar(entity, name, value)
    word = text.strip().lower()
    if word in TRUE_WORDS or word in FALSE_WORDS:
        return word in TRUE_WORDS
    if substitutions and "$(" in text:
        return _substituted(entity, text)
    raise entity.fail(
        f"attribute '{name}' of {entity.label} must be a boolean (true/false, yes/no, on/off), "
        f"not '{text}'"
    )


def _on_exit(entity: Entity) -> Any:
    """``on_exit="shutdown"``: the launch ends when the process does (the only word launch has)."""
    value = entity.value("on_exit")
    if value is None:
        return None
    text = _scalar(entity, "on_exit", value).strip()
    if text != "shutdown":
        raise entity.fail(
            f"attribute 'on_exit' of {entity.label} can only be 'shutdown', not '{text}'"
        )
    return [actions.Shutdown(reason=f"{entity.kind} exited (on_exit=shutdown)")]


def _number(entity: Entity, name: str) -> float | None:
    value = entity.value(name)
    if value is None:
        return None
    text = _scalar(entity, name, value)
    try:
        number = float(text)
    except ValueError:
        raise entity.fail(
            f"attribute '{name}' of {entity.label} must be a number, not '{text}'"
        ) from None
    if number < 0:
        raise entity.fail(f"attribute '{name}' of {entity.label} must not be negative")
    return number


def _count(entity: Entity, name: str) -> int | None:
    number = _number(entity, name)
    if number is not None and number != int(number):
        raise entity.fail(f"attribute '{name}' of {entity.label} must be a whole number")
    return None if number is None else int(number)


def _key(value: Any) -> Any:
    return tuple(value) if isinstance(value, list) else value


def _condition(entity: Entity) -> dict[str, Any]:
    if entity.value("if") is not None and entity.value("unless") is not None:
        raise entity.fail(f"{entity.label} cannot have both 'if' and 'unless'")
    if entity.value("if") is not None:
        return {"condition": IfCondition(_text(entity, "if"))}
    if entity.value("unless") is not None:
        return {"condition": UnlessCondition(_text(entity, "unless"))}
    return {}


def command_words(entity: Entity, name: str) -> list[Any] | None:
    """A command line attribute as words.

    Split at spaces outside quotes; a substitution is joined to the text it touches
    (``$(find-pkg-share p)/x.yaml`` is one word).
    """
    value = _text(entity, name)
    if value is None:
        return None
    words: list[list[Any]] = []
    word: list[Any] = []
    started = False
    quote: str | None = None
    for part in value if isinstance(value, list) else [value]:
        if not isinstance(part, str):
            word.append(part)
            started = True
            continue
        for char in part:
            if quote is not None:
                if char == quote:
                    quote = None
                else:
                    word.append(char)
            elif char in "'\"":
                quote = char
                started = True
            elif char.isspace():
                if started:
                    words.append(word)
                word, started = [], False
            else:
                word.append(char)
                started = True
    if quote is not None:
        raise entity.fail(f"attribute '{name}' of {entity.label} has an unclosed {quote}")
    if started:
        words.append(word)
    return [joined(w) if w else "" for w in words]


# --- tags -> actions -----------------------------------------------------------------------

_NAME_VALUE = _tag("name value")
_PARAM = _tag("name value type from allow_substs", "param")
_PROCESS = (
    "cwd name launch-prefix output respawn respawn_delay respawn_max_retries shell emulate_tty "
    "sigterm_timeout sigkill_timeout on_exit"
)
TAGS: dict[str, Tag] = {
    "arg": _tag("name default description", "choice"),
    "let": _NAME_VALUE,
    "set_env": _NAME_VALUE,
    "unset_env": _tag("name"),
    "append_env": _tag("name value prepend separator"),
    "log": _tag("message"),
    "shutdown": _tag("reason"),
    "push-ros-namespace": _tag("namespace"),
    "push_ros_namespace": _tag("namespace"),
    "group": _tag("scoped forwarding", "keep", children=True),
    "include": _tag("file", "arg let"),
    "timer": _tag("period", children=True),
    "executable": _tag(f"cmd {_PROCESS}", "env"),
    "node": _tag(f"pkg exec namespace exec_name args ros_args {_PROCESS}", "param remap env"),
    "lifecycle_node": _tag(
        f"pkg exec namespace exec_name args ros_args autostart {_PROCESS}", "param remap env"
    ),
    "set_parameter": _tag("name value"),
    "set_remap": _tag("from to"),
    "set_parameters_from_file": _tag("filename"),
    "set_use_sim_time": _tag("value"),
    "reset": _tag("", "keep"),
    "ros_timer": _tag("period", children=True),
    "for": _tag("len name", children=True),
    "for_each": _tag("values", children=True),
}
_NESTED = {
    "choice": _tag("value"),
    "keep": _NAME_VALUE,
    "arg": _NAME_VALUE,
    "let": _NAME_VALUE,
    "env": _NAME_VALUE,
    "remap": _tag("from to"),
    "param": _PARAM,
}
_PARAMETER_TYPES: dict[str, Any] = {
    "str": str, "int": int, "float": float, "bool": bool, "yaml": None,
    "list_of_str": [str], "list_of_int": [int], "list_of_float": [float], "list_of_bool": [bool],
}  # fmt: skip


def _nested(entity: Entity, name: str) -> list[Entity]:
    found = entity.nested(name)
    for item in found:
        item.check(_NESTED[name], guarded=False)
    return found


def _name_values(entity: Entity, name: str) -> list[tuple[Any, Any]]:
    return [
        (_key(_text(e, "name", required=True)), _text(e, "value", required=True))
        for e in _nested(entity, name)
    ]


def build_arg(entity: Entity) -> Any:
    """``<arg name default description>`` with ``<choice value>`` children."""
    choices = [_plain(c, "value", required=True) for c in _nested(entity, "choice")]
    return actions.DeclareLaunchArgument(
        _plain(entity, "name", required=True) or "",
        default_value=_text(entity, "default"),
        description=_plain(entity, "description") or actions.DEFAULT_DESCRIPTION,
        choices=[c or "" for c in choices] or None,
        **_condition(entity),
    )


def build_include(entity: Entity) -> Any:
    """``<include file>`` with ``<arg name value>`` (or ``<let>``) children."""
    return actions.IncludeLaunchDescription(
        actions.PythonLaunchDescriptionSource(_text(entity, "file", required=True)),
        launch_arguments=_name_values(entity, "arg") + _name_values(entity, "let"),
        **_condition(entity),
    )


def build_group(entity: Entity) -> Any:
    """``<group scoped forwarding>`` with ``<keep name value>`` and child actions."""
    scoped = _flag(entity, "scoped")
    forwarding = _flag(entity, "forwarding")
    return actions.GroupAction(
        _child_actions(entity),
        scoped=True if scoped is None else scoped,
        forwarding=True if forwarding is None else forwarding,
        launch_configurations=dict(_name_values(entity, "keep")),
        **_condition(entity),
    )


def build_timer(entity: Entity) -> Any:
    """``<timer period>`` with child actions."""
    return actions.TimerAction(
        period=_text(entity, "period", required=True),
        actions=_child_actions(entity),
        **_condition(entity),
    )


def _process(entity: Entity) -> dict[str, Any]:
    """What ``<executable>`` and ``<node>`` share (launch's ExecuteProcess.parse)."""
    options: dict[str, Any] = {
        "cwd": _text(entity, "cwd"),
        "name": _text(entity, "name"),
        "prefix": _text(entity, "launch-prefix"),
        "output": _text(entity, "output"),
        "respawn": _flag(entity, "respawn", substitutions=True),
        "respawn_delay": _number(entity, "respawn_delay"),
        "respawn_max_retries": _count(entity, "respawn_max_retries"),
        "shell": _flag(entity, "shell"),
        "emulate_tty": _flag(entity, "emulate_tty"),
        "sigterm_timeout": _text(entity, "sigterm_timeout"),
        "sigkill_timeout": _text(entity, "sigkill_timeout"),
        "additional_env": dict(_name_values(entity, "env")) or None,
        "on_exit": _on_exit(entity),
    }
    return {k: v for k, v in options.items() if v is not None} | _condition(entity)


def build_executable(entity: Entity) -> Any:
    """``<executable cmd cwd name shell output ...>`` with ``<env>`` children."""
    if entity.value("cmd") is None:
        raise entity.fail(f"{entity.label} needs the attribute 'cmd'")
    return actions.ExecuteProcess(cmd=command_words(entity, "cmd"), **_process(entity))


def build_node(entity: Entity) -> Any:
    """``<node pkg exec name namespace args ros_args ...>`` with param, remap, env children."""
    return _node(entity, ros_actions.Node)


def build_lifecycle_node(entity: Entity) -> Any:
    """``<lifecycle_node name namespace autostart ...>``: a ``<node>`` with a lifecycle."""
    from rosl.launch.lifecycle import LifecycleNode

    if entity.value("name") is None:
        raise entity.fail(f"{entity.label} needs the attribute 'name'")
    return _node(entity, LifecycleNode, autostart=_flag(entity, "autostart", substitutions=True))


def _node(entity: Entity, kind: Any, **extra: Any) -> Any:
    options = _process(entity)
    return kind(
        package=_text(entity, "pkg", required=True),
        executable=_text(entity, "exec", required=True),
        namespace=_text(entity, "namespace"),
        exec_name=_text(entity, "exec_name"),
        parameters=parameters(entity),
        remappings=[
            (_text(r, "from", required=True), _text(r, "to", required=True))
            for r in _nested(entity, "remap")
        ],
        arguments=command_words(entity, "args"),
        ros_arguments=command_words(entity, "ros_args"),
        **extra,
        **options,
    )


def parameters(entity: Entity) -> list[Any]:
    """A node's ``<param>``s: ``name``+``value`` (or nested params) in dicts, ``from`` files."""
    found: list[Any] = []
    for param in _nested(entity, "param"):
        if param.value("from") is not None:
            if param.value("name") is not None or param.nested("param"):
                raise param.fail(f"{param.label} with 'from' has no 'name' and no nested params")
            allow = _flag(param, "allow_substs", substitutions=True)
            source = _text(param, "from")
            found.append(ros_actions.ParameterFile(source, allow_substs=allow) if allow else source)
            continue
        if not found or not isinstance(found[-1], dict):
            found.append({})
        found[-1].update(_parameter_items(param, []))
    return found


def _parameter_items(param: Entity, prefix: list[Any]) -> Iterator[tuple[Any, Any]]:
    name = _text(param, "name", required=True)
    parts = [*prefix, *(["."] if prefix else []), *(name if isinstance(name, list) else [name])]
    key = _key(joined(parts))
    children = _nested(param, "param")
    raw = param.value("value")
    if children:
        if raw is not None or param.value("type") is not None:
            raise param.fail(f"{param.label} with nested params has no 'value' and no 'type'")
        for child in children:
            yield from _parameter_items(child, parts)
    elif raw is None:
        raise param.fail(f"parameter {name!r} needs 'value', 'from' or nested params")
    else:
        yield key, _parameter_value(param, raw)


def _parameter_value(param: Entity, raw: Any) -> Any:
    """A value typed as launch_ros types it: by YAML rules, or by the ``type`` attribute."""
    type_name = _plain(param, "type")
    if type_name is not None and type_name not in _PARAMETER_TYPES:
        raise param.fail(
            f"unknown parameter type '{type_name}' (one of: {', '.join(_PARAMETER_TYPES)})"
        )
    kind = _PARAMETER_TYPES.get(type_name or "yaml")
    if isinstance(raw, list):
        return [_typed_item(param, item, kind[0] if kind else None) for item in raw]
    if isinstance(kind, list):
        raise param.fail(f"a parameter of type '{type_name}' needs a list (value-sep=...)")
    return _typed_item(param, raw, kind)


def _typed_item(param: Entity, raw: Any, kind: Any) -> Any:
    if isinstance(raw, (dict, list)) or raw is None:
        raise param.fail(f"parameter value {raw!r} is not a single value; use nested params")
    value = raw
    if isinstance(raw, str):
        parsed = _substituted(param, raw)
        if not isinstance(parsed, str):  # typed once substituted (ParameterValue)
            return parsed if kind is None else ros_actions.ParameterValue(parsed, value_type=kind)
        if kind is str:
            return parsed
        value = param.typed(parsed) if kind is None else ros_actions.yaml_typed(parsed)
    if kind is None or kind is str:
        return str(value).lower() if kind is str and isinstance(value, bool) else value
    if isinstance(value, bool) != (kind is bool) or not isinstance(value, (int, float)):
        raise param.fail(f"parameter value {raw!r} is not of type {kind.__name__}")
    if kind is int and not isinstance(value, int):
        raise param.fail(f"parameter value {raw!r} is not of type int")
    return kind(value)


def _set_parameter(entity: Entity) -> Any:
    if entity.value("value") is None:
        raise entity.fail(f"{entity.label} needs the attribute 'value'")
    return ros_actions.SetParameter(
        _text(entity, "name", required=True),
        _parameter_value(entity, entity.value("value")),
        **_condition(entity),
    )


def _unset_env(entity: Entity) -> Any:
    unset = getattr(actions, "UnsetEnvironmentVariable", None)
    if unset is None:
        raise entity.fail(f"{entity.label} is not supported by rosl yet")
    return unset(_text(entity, "name", required=True), **_condition(entity))


def build_for(entity: Entity) -> Any:
    """``<for len= name=>``: its children once per index, ``$(index NAME)`` in them."""
    from rosl.launch import loops

    name = _plain(entity, "name", required=True) or ""
    return loops.ForLoop(
        _text(entity, "len", required=True),
        function=lambda i: [loops.Iteration({name: i}, _child_actions(entity))],
        name=name,
        **_condition(entity),
    )


def build_for_each(entity: Entity) -> Any:
    """``<for_each values=>``: its children once per value set, ``$(for-var NAME)`` in them."""
    from rosl.launch import loops

    return loops.ForEach(
        _text(entity, "values", required=True),
        function=loops.frontend_body(lambda: _child_actions(entity)),
        **_condition(entity),
    )


BUILDERS: dict[str, Callable[[Entity], Any]] = {
    "arg": build_arg,
    "let": lambda e: actions.SetLaunchConfiguration(
        _text(e, "name", required=True), _text(e, "value", required=True), **_condition(e)
    ),
    "set_env": lambda e: actions.SetEnvironmentVariable(
        _text(e, "name", required=True), _text(e, "value", required=True), **_condition(e)
    ),
    "unset_env": _unset_env,
    "append_env": lambda e: actions.AppendEnvironmentVariable(
        _text(e, "name", required=True),
        _text(e, "value", required=True),
        prepend=_flag(e, "prepend", substitutions=True) or False,
        **({"separator": _text(e, "separator")} if e.value("separator") is not None else {}),
        **_condition(e),
    ),
    "log": lambda e: actions.LogInfo(msg=_text(e, "message", required=True), **_condition(e)),
    "shutdown": lambda e: actions.Shutdown(
        reason=_plain(e, "reason") or "shutdown requested", **_condition(e)
    ),
    "push-ros-namespace": lambda e: ros_actions.PushRosNamespace(
        _text(e, "namespace", required=True), **_condition(e)
    ),
    "group": build_group,
    "include": build_include,
    "timer": build_timer,
    "executable": build_executable,
    "node": build_node,
    "lifecycle_node": build_lifecycle_node,
    "set_parameter": _set_parameter,
    "set_remap": lambda e: ros_actions.SetRemap(
        _text(e, "from", required=True), _text(e, "to", required=True), **_condition(e)
    ),
    "set_parameters_from_file": lambda e: ros_actions.SetParametersFromFile(
        _text(e, "filename", required=True), **_condition(e)
    ),
    "set_use_sim_time": lambda e: ros_actions.SetUseSimTime(
        _flag(e, "value", substitutions=True) if e.value("value") is not None else True,
        **_condition(e),
    ),
    "reset": lambda e: actions.ResetLaunchConfigurations(
        dict(_name_values(e, "keep")) or None, **_condition(e)
    ),
    "for": build_for,
    "for_each": build_for_each,
    "ros_timer": lambda e: ros_actions.RosTimer(
        period=_text(e, "period", required=True), actions=_child_actions(e), **_condition(e)
    ),
}
BUILDERS["push_ros_namespace"] = BUILDERS["push-ros-namespace"]

_COMPONENTS = "it runs C++ components, which rosl cannot (start each as a <node> instead)"
_REFUSED = {
    "node_container": _COMPONENTS,
    "load_composable_node": _COMPONENTS,
}


def build_action(entity: Entity) -> Any:
    """The action for one tag; errors it raises while it runs name the tag's line.

    Raises:
        LaunchError: an unknown tag or attribute, a missing or bad value (``file:line:``).
    """
    from rosl.idl.names import did_you_mean

    if entity.kind in _REFUSED:
        raise entity.fail(f"{entity.label} is not supported: {_REFUSED[entity.kind]}")
    if entity.kind not in BUILDERS:
        raise entity.fail(
            f"unknown {entity.noun} {entity.label}{did_you_mean(entity.kind, BUILDERS)} "
            f"(rosl reads: {', '.join(BUILDERS)})"
        )
    entity.check(TAGS[entity.kind], guarded=True)
    action = BUILDERS[entity.kind](entity)
    action.location = f"{entity.path}:{entity.line}"  # errors it raises when it runs name it
    return action


def build_actions(entities: list[Entity]) -> list[Any]:
    """The actions of a list of tags, in order."""
    return [build_action(entity) for entity in entities]


def build_description(root: Entity) -> LaunchDescription:
    """The LaunchDescription of a launch file's root entity (``<launch>`` / ``launch:``)."""
    return LaunchDescription(build_actions(root.actions()))


def _child_actions(entity: Entity) -> list[Any]:
    nested = TAGS[entity.kind].nested
    return build_actions([child for child in entity.actions() if child.kind not in nested])
