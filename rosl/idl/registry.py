"""Interface types by name: find the file, parse it, resolve its references, build its class.

Everything is loaded on first use and cached for the life of the process, so a .msg file
saved a moment ago is used by the next process that asks for it — no build step. References
resolve as rosidl does (``Name`` is the same package's, ``pkg/Name`` another's), plus the
ROS 1 habit ``Header`` meaning ``std_msgs/Header`` when the package has no Header of its own.
"""

from __future__ import annotations

import dataclasses
import threading
from typing import TYPE_CHECKING

from rosl.idl import search_path
from rosl.idl.errors import InterfaceError
from rosl.idl.names import TypeName, base_name, did_you_mean, parse_type_name
from rosl.idl.parser import (
    ActionSpec,
    FieldType,
    MessageSpec,
    ServiceSpec,
    parse_action,
    parse_message,
    parse_service,
)

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from rosl.idl.base import ActionType
    from rosl.idl.messages import Message, ServiceType
    from rosl.idl.store import Store

Spec = MessageSpec | ServiceSpec | ActionSpec
_lock = threading.RLock()
_specs: dict[str, Spec] = {}
_classes: dict[str, type[Message]] = {}
_services: dict[str, type[ServiceType]] = {}
_actions: dict[str, type[ActionType]] = {}
_loading: list[str] = []
_store: Store | None = None
_clear_hooks: list[Callable[[], None]] = []  # e.g. import-hook modules dropping cached classes


def store() -> Store:
    """Return the process-wide CDR store (created on first use)."""
    global _store
    if _store is None:
        from rosl.idl.store import Store

        _store = Store()
    return _store


def interface_path(name: TypeName) -> Path:
    """Return the file defining ``name`` (which may not exist)."""
    base = base_name(name.name, name.kind)
    package = search_path.find_package(name.package)
    return package.path / name.kind / f"{base}.{name.kind}"


def list_types(package: str, kind: str) -> list[str]:
    """Return the type names (``Name``) of one kind that ``package`` defines, sorted."""
    folder = search_path.find_package(package).path / kind
    if not folder.is_dir():
        return []
    return sorted(p.stem for p in folder.glob(f"*.{kind}") if p.is_file())


def load_spec(type_name: str) -> Spec:
    """Parse the definition of a canonical type name (cached).

    An action's generated types (``pkg/action/Name_SendGoal``...) come from its file.

    Raises:
        InterfaceError: unknown package or type (with close names), or a bad file.
    """
    name = parse_type_name(type_name)
    key = str(name)
    if name.kind == "srv" and name.name.endswith("_Event"):
        return _event_spec(name)
    if name.kind == "srv" and name.name.endswith(("_Request", "_Response")):
        service = load_spec(f"{name.package}/srv/{_service_base(name.name)}")
        assert isinstance(service, ServiceSpec)
        return service.request if name.name.endswith("_Request") else service.response
    if name.kind == "action" and name.name != base_name(name.name, "action"):
        from rosl.idl.action_types import derived_spec

        base = base_name(name.name, "action")
        action = load_spec(f"{name.package}/action/{base}")
        assert isinstance(action, ActionSpec)
        return derived_spec(action, name.name[len(base) :])
    with _lock:
        if key in _specs:
            return _specs[key]
        path = interface_path(name)
        if not path.is_file():
            raise InterfaceError(_missing_message(name, path))
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as err:
            raise InterfaceError(f"cannot read {name}: {err}", path) from None
        if name.kind == "msg":
            spec: Spec = parse_message(text, key, path)
        elif name.kind == "srv":
            spec = parse_service(text, key, path)
        else:
            spec = parse_action(text, key, path)
        _specs[key] = spec
        return spec


def _service_base(name: str) -> str:
    return name.removesuffix("_Request").removesuffix("_Response").removesuffix("_Event")


def _event_spec(name: TypeName) -> MessageSpec:
    """ROS 2 (Jazzy) service introspection's ``<Service>_Event``: info, request, response."""
    from rosl.idl.parser import ArrayKind, Field

    base = _service_base(name.name)
    service = load_spec(f"{name.package}/srv/{base}")
    assert isinstance(service, ServiceSpec)
    prefix = f"{name.package}/srv/{base}"
    text = (
        "service_msgs/msg/ServiceEventInfo info\n"
        f"{prefix}_Request[<=1] request\n{prefix}_Response[<=1] response\n"
    )
    fields = (
        Field("info", FieldType("service_msgs/msg/ServiceEventInfo"), written="ServiceEventInfo"),
        Field("request", FieldType(f"{prefix}_Request", ArrayKind.BOUNDED, 1), written="x"),
        Field("response", FieldType(f"{prefix}_Response", ArrayKind.BOUNDED, 1), written="x"),
    )
    return MessageSpec(str(name), fields, (), service.path, text)


def _missing_message(name: TypeName, path: Path) -> str:
    others = list_types(name.package, name.kind)
    hint = did_you_mean(name.name, others)
    if not hint and name.kind == "msg" and name.name in list_types(name.package, "srv"):
        hint = f" (there is a service '{name.package}/srv/{name.name}')"
    return (
        f"unknown type '{name}': there is no {name.kind}/{path.name} in package "
        f"'{name.package}' ({path.parent.parent}){hint}"
    )


def exists(type_name: str) -> bool:
    """Whether a canonical message type can be found (without parsing it)."""
    try:
        name = parse_type_name(type_name)
        return interface_path(name).is_file()
    except InterfaceError:
        return False


def resolve(spec: MessageSpec) -> MessageSpec:
    """Return ``spec`` with every field type pointing at an existing message type.

    Raises:
        InterfaceError: a referenced type does not exist, located at the field in the file.
    """
    fields = []
    for field in spec.fields:
        ftype = field.type
        if not ftype.is_primitive and not exists(ftype.base):
            written = field.written.split("[")[0]
            if written == "Header" and exists("std_msgs/msg/Header"):
                ftype = dataclasses.replace(ftype, base="std_msgs/msg/Header")
            else:
                raise InterfaceError(
                    _reference_message(written, ftype), spec.path, field.line, field.col
                )
        fields.append(dataclasses.replace(field, type=ftype))
    return dataclasses.replace(spec, fields=tuple(fields))


def _reference_message(written: str, ftype: FieldType) -> str:
    name = parse_type_name(ftype.base)
    result = search_path.scan()
    if name.package not in result.packages:
        return f"unknown type '{written}': " + search_path.unknown_package_message(
            name.package, result
        )
    folder = result.packages[name.package].path
    hint = did_you_mean(name.name, list_types(name.package, "msg"))
    return (
        f"unknown type '{written}': there is no msg/{name.name}.msg in package "
        f"'{name.package}' ({folder}){hint}"
    )


def get_message_class(type_name: str) -> type[Message]:
    """Return the class of a message type (or service half), building it on first use.

    Raises:
        InterfaceError: the type or one it depends on is unknown or badly defined.
    """
    key = str(parse_type_name(type_name))
    cached = _classes.get(key)
    if cached is not None:
        return cached
    with _lock:
        if key in _classes:
            return _classes[key]
        if key in _loading:
            cycle = " -> ".join([*_loading[_loading.index(key) :], key])
            raise InterfaceError(f"recursive message definition: {cycle}")
        spec = load_spec(key)
        if isinstance(spec, ServiceSpec):
            raise InterfaceError(f"'{key}' is a service; use '{key}' with a service API")
        if isinstance(spec, ActionSpec):
            raise InterfaceError(f"'{key}' is an action; use '{key}' with an action API")
        _loading.append(key)
        try:
            return _build(resolve(spec))
        finally:
            _loading.pop()


def _build(spec: MessageSpec) -> type[Message]:
    from rosl.idl.messages import build_message_class

    field_classes = {
        f.type.base: get_message_class(f.type.base) for f in spec.fields if not f.type.is_primitive
    }
    cls = build_message_class(spec, field_classes)
    store().add(spec, cls)
    _classes[spec.type_name] = cls
    return cls


def get_service_class(type_name: str) -> type[ServiceType]:
    """Return the class of a service type (with ``Request``/``Response``), built on first use."""
    key = str(parse_type_name(type_name, "srv"))
    cached = _services.get(key)
    if cached is not None:
        return cached
    with _lock:
        spec = load_spec(key)
        if not isinstance(spec, ServiceSpec):
            raise InterfaceError(f"'{key}' is not a service")
        from rosl.idl.messages import build_service_class

        request = get_message_class(spec.request.type_name)
        response = get_message_class(spec.response.type_name)
        cls = build_service_class(key, request, response)
        _services[key] = cls
        return cls


def get_interface(type_name: str) -> type[Message] | type[ServiceType] | type[ActionType]:
    """Return the class for a message or service type name.

    Args:
        type_name: ``pkg/msg/Name``, ``pkg/srv/Name`` or ``pkg/Name`` (a message if both exist).

    Returns:
        A message class, a service class with ``Request`` and ``Response``, or an action
        class.

    Raises:
        InterfaceError: unknown or badly defined type.
    """
    name = parse_type_name(type_name)
    if type_name.count("/") == 1 and not exists(str(name)):
        srv = TypeName(name.package, "srv", name.name)
        try:
            if interface_path(srv).is_file():
                return get_service_class(str(srv))
        except InterfaceError:
            pass
    if name.kind == "srv" and not name.name.endswith(("_Request", "_Response")):
        return get_service_class(str(name))
    if name.kind == "action" and name.name == base_name(name.name, "action"):
        return get_action_class(str(name))
    if name.kind == "action" and name.name.endswith(("_SendGoal", "_GetResult")):
        return get_service_class(str(name))
    return get_message_class(str(name))


def get_action_class(type_name: str) -> type[ActionType]:
    """Return the class of an action type, as rosidl_generator_py makes it (built on first use).

    It holds ``Goal``, ``Result``, ``Feedback`` and ``Impl`` (``SendGoalService``,
    ``GetResultService``, ``FeedbackMessage``, ``CancelGoalService``, ``GoalStatusMessage``).

    Raises:
        InterfaceError: unknown or badly defined action (or a type it uses).
    """
    key = str(parse_type_name(type_name, "action"))
    cached = _actions.get(key)
    if cached is not None:
        return cached
    with _lock:
        spec = load_spec(key)
        if not isinstance(spec, ActionSpec):
            raise InterfaceError(f"'{key}' is not an action")
        from rosl.idl.messages import build_action_class

        cls = build_action_class(
            key,
            {
                part: get_message_class(f"{key}{part}")
                for part in ("_Goal", "_Result", "_Feedback", "_FeedbackMessage")
            },
            {part: get_service_class(f"{key}{part}") for part in ("_SendGoal", "_GetResult")},
            get_service_class("action_msgs/srv/CancelGoal"),
            get_message_class("action_msgs/msg/GoalStatusArray"),
        )
        _actions[key] = cls
        return cls


KINDS = ("msg", "srv", "action")


def package_types(package: str, kinds: tuple[str, ...] = KINDS) -> list[str]:
    """Return ``pkg/kind/Name`` for every interface of ``kinds`` in ``package``.

    Raises:
        InterfaceError: unknown package.
    """
    return [f"{package}/{kind}/{name}" for kind in kinds for name in list_types(package, kind)]


def all_types() -> dict[str, list[str]]:
    """Return every interface on the search path, per kind, sorted (first package wins)."""
    result = search_path.scan()
    return {
        kind: [
            f"{package}/{kind}/{name}"
            for package in sorted(result.packages)
            for name in list_types(package, kind)
        ]
        for kind in KINDS
    }


def interface_packages(kinds: tuple[str, ...] = KINDS) -> list[str]:
    """Return the sorted names of packages that define interfaces of ``kinds``."""
    result = search_path.scan()
    return [
        package
        for package in sorted(result.packages)
        if any(list_types(package, kind) for kind in kinds)
    ]


def clear() -> None:
    """Forget every loaded type and class (later lookups read the files again)."""
    global _store
    with _lock:
        _specs.clear()
        _classes.clear()
        _services.clear()
        _actions.clear()
        _store = None
    search_path.rescan()
    for hook in _clear_hooks:
        hook()


def on_clear(hook: Callable[[], None]) -> None:
    """Call ``hook`` whenever :func:`clear` forgets the loaded types."""
    if hook not in _clear_hooks:
        _clear_hooks.append(hook)


DELIMITER = "=" * 80


def msgdef_text(type_name: str) -> str:
    """The full ``ros2msg`` text of a type, as rosbag2 writes MCAP schemas.

    The type's own text, then each message type it uses (sorted, each once, recursively)
    after a line of 80 ``=`` and ``MSG: pkg/Name`` — without ``/msg/``, as rosbag2 and
    rosbags write it and as Foxglove's ros2msg parser needs it.

    Raises:
        InterfaceError: unknown type.
    """
    seen: set[str] = set()

    def text_of(name: str) -> str:
        spec = load_spec(name)
        assert isinstance(spec, MessageSpec)
        resolved = resolve(spec)
        result = spec.text if spec.text.endswith("\n") or not spec.text else spec.text + "\n"
        for dependency in sorted({f.type.base for f in resolved.fields if not f.type.is_primitive}):
            if dependency not in seen:
                seen.add(dependency)
                header = dependency.replace("/msg/", "/", 1)
                result += f"\n{DELIMITER}\nMSG: {header}\n{text_of(dependency)}"
        return result

    key = str(parse_type_name(type_name))
    get_message_class(key)
    return text_of(key)


def digest(type_name: str) -> str:
    """A short fingerprint of a loaded type's definition (the start of its RIHS01 hash).

    Discovery carries it with each endpoint, so a subscription can tell a publisher whose
    .msg file says something else under the same type name. Empty when it cannot be made.
    """
    try:
        return store().type_hash(type_name)[7:23]
    except Exception:  # rosbags raises several kinds for a type it cannot hash
        return ""


def loaded(type_name: str) -> bool:
    """Whether a type's class was built in this process (so its definition is at hand)."""
    return type_name in _classes


def schema(type_name: str) -> tuple[str, str]:
    """(encoding, text) of the MCAP schema rosbag2 writes: ros2msg, or ros2idl for srv types.

    A service's types (``pkg/srv/Name_Event`` of service introspection) have no ``.msg`` file,
    and rosbag2 falls back to IDL for them. ros2msg cannot carry them for every reader:
    rosbags (0.11) files any ``pkg/srv/X`` ros2msg root under ``pkg/srv/msg/X`` and then
    neither finds nor hashes it, so a Jazzy-layout bag would not open at all. IDL is read by
    rosbags and by Foxglove (its ros2idl parser); mcap-ros2-support (0.6) decodes ros2msg only
    and leaves these topics undecoded.
    """
    if "/srv/" in type_name or "/action/" in type_name:  # an action's feedback: the same
        from rosl.idl.idl_text import full_idl

        return "ros2idl", full_idl(type_name)
    return "ros2msg", msgdef_text(type_name)
