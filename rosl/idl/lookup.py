"""Interfaces by full name and per package, as ``rosidl_runtime_py`` finds them.

``get_interface('std_msgs/msg/String')`` returns the class; ``get_message``/``get_service``/
``get_action`` add the default kind to a two-part name and check what they got. Unknown names
fail as the import that rosidl_runtime_py does would fail: ``ModuleNotFoundError`` for a
package (or kind) that has no module, ``AttributeError`` for a name its module lacks, and
``ValueError`` for an interface of the wrong kind. Kinds other than ``msg``/``srv`` (actions)
are imported, so they resolve wherever an import hook serves them. Listings name interfaces
as ``msg/Name``; an unknown package is a ``LookupError``.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosl.idl import registry, search_path
from rosl.idl.base import Message, ServiceType
from rosl.idl.errors import InterfaceError

if TYPE_CHECKING:
    from collections.abc import Iterable

_KINDS = ("msg", "srv")


@dataclass(frozen=True, slots=True)
class NamespacedType:
    """A type name split as rosidl_parser holds it: ``(['std_msgs', 'msg'], 'String')``."""

    namespaces: tuple[str, ...]
    name: str

    def namespaced_name(self) -> tuple[str, ...]:
        """The namespaces followed by the name."""
        return (*self.namespaces, self.name)


def get_namespaced_type(identifier: str, default_kind: str | None = None) -> NamespacedType:
    """Split ``pkg/kind/Name`` (or ``pkg/Name``, which takes ``default_kind``)."""
    *namespaces, name = identifier.split("/")
    if len(namespaces) == 1 and default_kind is not None:
        namespaces.append(default_kind)
    return NamespacedType(tuple(namespaces), name)


def get_message_namespaced_type(identifier: str) -> NamespacedType:
    """Split a message's name (``pkg/Name`` means ``pkg/msg/Name``)."""
    return get_namespaced_type(identifier, "msg")


def get_service_namespaced_type(identifier: str) -> NamespacedType:
    """Split a service's name (``pkg/Name`` means ``pkg/srv/Name``)."""
    return get_namespaced_type(identifier, "srv")


def get_action_namespaced_type(identifier: str) -> NamespacedType:
    """Split an action's name (``pkg/Name`` means ``pkg/action/Name``)."""
    return get_namespaced_type(identifier, "action")


def import_interface(namespaced: NamespacedType) -> Any:
    """Return the class a namespaced type names (errors as its import would raise them)."""
    module = ".".join(namespaced.namespaces)
    if len(namespaced.namespaces) != 2 or namespaced.namespaces[1] not in _KINDS:
        return getattr(importlib.import_module(module), namespaced.name)
    package, kind = namespaced.namespaces
    try:
        folder = search_path.find_package(package).path / kind
    except InterfaceError:
        raise ModuleNotFoundError(f"No module named '{package}'", name=package) from None
    if not folder.is_dir():
        raise ModuleNotFoundError(f"No module named '{module}'", name=module)
    if namespaced.name not in registry.list_types(package, kind):
        raise AttributeError(f"module '{module}' has no attribute '{namespaced.name}'")
    return registry.get_interface(f"{package}/{kind}/{namespaced.name}")


def is_message(interface: Any) -> bool:
    """Whether ``interface`` is a message class."""
    return isinstance(interface, type) and issubclass(interface, Message)


def is_service(interface: Any) -> bool:
    """Whether ``interface`` is a service class (it has ``Request`` and ``Response``)."""
    return isinstance(interface, type) and issubclass(interface, ServiceType)


def is_action(interface: Any) -> bool:
    """Whether ``interface`` is an action class (``Goal``, ``Result`` and ``Feedback``)."""
    return all(hasattr(interface, part) for part in ("Goal", "Result", "Feedback"))


def get_interface(identifier: str) -> Any:
    """Return the interface class a full name (``pkg/kind/Name``) names."""
    return import_interface(get_namespaced_type(identifier))


def get_message(identifier: str) -> Any:
    """Return a message class (``pkg/Name`` means ``pkg/msg/Name``).

    Raises:
        ValueError: the name is not a message's.
    """
    return _checked(identifier, "msg", is_message, "a message")


def get_service(identifier: str) -> Any:
    """Return a service class (``pkg/Name`` means ``pkg/srv/Name``).

    Raises:
        ValueError: the name is not a service's.
    """
    return _checked(identifier, "srv", is_service, "a service")


def get_action(identifier: str) -> Any:
    """Return an action class (``pkg/Name`` means ``pkg/action/Name``).

    Raises:
        ValueError: the name is not an action's.
    """
    return _checked(identifier, "action", is_action, "an action")


def _checked(identifier: str, kind: str, check: Any, what: str) -> Any:
    interface = import_interface(get_namespaced_type(identifier, kind))
    if not check(interface):
        raise ValueError(f"Expected the full name of {what}, got '{identifier}'")
    return interface


# --- listings ---------------------------------------------------------------------------------


def get_interface_packages() -> list[str]:
    """The names of the packages that define interfaces."""
    return registry.interface_packages()


def get_interfaces(
    package_names: Iterable[str] = (), kinds: tuple[str, ...] = ()
) -> dict[str, list[str]]:
    """Each package's interfaces as ``kind/Name`` (packages with none are left out).

    Args:
        package_names: the packages to list (every interface package when empty).
        kinds: the kinds to list (``msg``, ``srv``, ``action``; all when empty).

    Raises:
        LookupError: a package that does not exist.
    """
    wanted = kinds or registry.KINDS
    names = list(package_names) or registry.interface_packages()
    found: dict[str, list[str]] = {}
    for package in names:
        try:
            types = registry.package_types(package, wanted)
        except InterfaceError:
            raise LookupError(f"Unknown package '{package}'") from None
        if types:
            found[package] = [t.split("/", 1)[1] for t in types]
    return found


def get_message_interfaces(package_names: Iterable[str] = ()) -> dict[str, list[str]]:
    """Each package's messages as ``msg/Name`` (see :func:`get_interfaces`)."""
    return get_interfaces(package_names, ("msg",))


def get_service_interfaces(package_names: Iterable[str] = ()) -> dict[str, list[str]]:
    """Each package's services as ``srv/Name`` (see :func:`get_interfaces`)."""
    return get_interfaces(package_names, ("srv",))


def get_action_interfaces(package_names: Iterable[str] = ()) -> dict[str, list[str]]:
    """Each package's actions as ``action/Name`` (see :func:`get_interfaces`)."""
    return get_interfaces(package_names, ("action",))


def get_interface_path(interface_name: str) -> str:
    """The file defining an interface (``pkg/msg/Name``, with or without its suffix).

    Raises:
        ValueError: a name of fewer than two parts, an empty part, or ``..``.
        LookupError: an unknown package, or no such file.
    """
    parts = interface_name.split("/")
    if len(parts) < 2:
        raise ValueError(
            f"Invalid name '{interface_name}'. Expected at least two parts separated by '/'"
        )
    if not all(parts):
        raise ValueError(f"Invalid name '{interface_name}'. Must not contain empty parts")
    if ".." in parts:
        raise ValueError(f"Invalid name '{interface_name}'. Must not contain '..'")
    try:
        root = search_path.find_package(parts[0]).path
    except InterfaceError:
        raise LookupError(f"Unknown package '{parts[0]}'") from None
    path = root.joinpath(*parts[1:])
    if "." not in parts[-1]:
        path = path.with_name(f"{path.name}.{parts[-2]}")
    if not path.is_file():
        raise LookupError(f"Could not find the interface '{path}'")
    return str(path)
