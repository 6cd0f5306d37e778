"""The meta-path finder behind ``from geometry_msgs.msg import Twist``."""

from __future__ import annotations

import importlib.machinery
import sys
import threading
import types
from typing import TYPE_CHECKING, Any

# imported up front: importing them from inside find_spec, while another module is half
# imported (copy imports org.python.core), would re-enter that half-built module
from rosl.idl import search_path

if TYPE_CHECKING:
    from importlib.abc import Loader as LoaderBase
else:
    LoaderBase = object  # importlib.abc costs an import of ~6 ms; a loader needs no base

_KINDS = ("msg", "srv", "action")
_busy = threading.local()  # set while the finder itself imports or scans


class InterfaceModule(types.ModuleType):
    """``<pkg>.msg`` / ``.srv`` / ``.action``: attributes are interface classes, built when used."""

    def __init__(self, name: str, package: str, kind: str) -> None:
        super().__init__(name)
        self.__rosl_package__ = package
        self.__rosl_kind__ = kind

    def __getattr__(self, attr: str) -> Any:
        if attr.startswith("__"):
            if attr == "__all__":
                return self.__dir__()
            raise AttributeError(attr)
        from rosl.idl import registry

        if attr not in registry.list_types(self.__rosl_package__, self.__rosl_kind__):
            raise AttributeError(
                f"module '{self.__name__}' has no interface '{attr}' "
                f"(no {self.__rosl_kind__}/{attr}.{self.__rosl_kind__} in package "
                f"'{self.__rosl_package__}')"
            )
        value = registry.get_interface(f"{self.__rosl_package__}/{self.__rosl_kind__}/{attr}")
        setattr(self, attr, value)
        return value

    def __dir__(self) -> list[str]:
        from rosl.idl import registry

        return registry.list_types(self.__rosl_package__, self.__rosl_kind__)


class _Loader(LoaderBase):
    def __init__(self, package: str, kind: str | None) -> None:
        self.package = package
        self.kind = kind

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        if self.kind is None:
            module = types.ModuleType(spec.name)
            module.__path__ = []
            return module
        from rosl.idl import registry

        registry.on_clear(_forget_cached_classes)
        module = InterfaceModule(spec.name, self.package, self.kind)
        module.__file__ = str(search_path.find_package(self.package).path / self.kind)
        return module

    def exec_module(self, module: types.ModuleType) -> None:
        return None


def _is_interface_package(name: str, kind: str | None) -> bool:
    """Whether ``name`` has interfaces (of ``kind``: no ``std_msgs.srv`` module, as in ROS 2)."""
    found = search_path.scan().packages.get(name)  # a miss is common here: no error built
    kinds = _KINDS if kind is None else (kind,)
    return found is not None and any((found.path / k).is_dir() for k in kinds)


def _is_real(spec: importlib.machinery.ModuleSpec | None) -> bool:
    return spec is not None and spec.origin not in (None, "namespace")


class InterfaceFinder:  # a meta path finder
    """Serve ``<pkg>`` and ``<pkg>.msg``/``.srv``/``.action`` for interface packages.

    It sits just before the standard path finder and defers to any real module of the same
    name, so installed Python packages always win; namespace folders (a ``msg/`` folder on
    ``sys.path``) do not count as real.
    """

    def find_spec(
        self, fullname: str, path: Any = None, target: types.ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        """Return a spec for an interface module, or None to let others look."""
        parts = fullname.split(".")
        if len(parts) > 2 or (len(parts) == 2 and parts[1] not in _KINDS):
            return None
        if getattr(_busy, "active", False):
            return None
        _busy.active = True
        try:
            if _is_real(importlib.machinery.PathFinder.find_spec(fullname, path)):
                return None
            if not _is_interface_package(parts[0], parts[1] if len(parts) == 2 else None):
                return None
        finally:
            _busy.active = False
        kind = parts[1] if len(parts) == 2 else None
        is_package = kind is None
        return importlib.machinery.ModuleSpec(
            fullname, _Loader(parts[0], kind), is_package=is_package
        )


_finder = InterfaceFinder()


def _forget_cached_classes() -> None:
    for module in list(sys.modules.values()):
        if isinstance(module, InterfaceModule):
            for attr in [a for a in vars(module) if not a.startswith("__")]:
                delattr(module, attr)


def install() -> None:
    """Add the finder to ``sys.meta_path`` (once), just before the path finder."""
    if _finder in sys.meta_path:
        return
    index = next(
        (i for i, f in enumerate(sys.meta_path) if f is importlib.machinery.PathFinder),
        len(sys.meta_path),
    )
    sys.meta_path.insert(index, _finder)
