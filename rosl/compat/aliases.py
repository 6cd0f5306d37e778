"""The meta-path finder behind ``import rclpy`` (and ``launch``, ``launch_ros``) under rosl.

Each alias module is filled from its rosl counterpart, so ``rclpy.node.Node is rosl.Node``.
By default an installed real module of the same name wins; processes rosl starts (``rosl
run``/``launch``) force the aliases, since a real rclpy would talk DDS, not rosl's bus.
"""

from __future__ import annotations

import importlib
import importlib.machinery
import importlib.util
import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import types
    from importlib.abc import Loader as LoaderBase
else:
    LoaderBase = object  # importlib.abc costs an import of ~6 ms; a loader needs no base

ALIASES: dict[str, str] = {
    "rclpy": "rosl.compat.rclpy",
    "launch": "rosl.compat.launch",
    "launch_ros": "rosl.compat.launch_ros",
    "launch_testing": "rosl.compat.launch_testing",
    "launch_testing_ros": "rosl.compat.launch_testing_ros",
    "launch_xml": "rosl.compat.launch_xml",
    "launch_yaml": "rosl.compat.launch_yaml",
    "ament_index_python": "rosl.compat.ament_index_python",
    "rosidl_runtime_py": "rosl.compat.rosidl_runtime_py",
    "sensor_msgs_py": "rosl.compat.sensor_msgs_py",
    "tf2_ros": "rosl.compat.tf2_ros",
    "tf2_py": "rosl.compat.tf2_py",
    "tf2_geometry_msgs": "rosl.compat.tf2_geometry_msgs",
}


class _AliasLoader(LoaderBase):
    def __init__(self, target: str) -> None:
        self.target = target

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType | None:
        return None  # a fresh module; exec_module fills it

    def exec_module(self, module: types.ModuleType) -> None:
        source = importlib.import_module(self.target)
        for key, value in vars(source).items():
            if not key.startswith("__") or key in ("__all__", "__doc__", "__getattr__"):
                setattr(module, key, value)


class AliasFinder:  # a meta path finder
    """Serve ``rclpy.*`` from ``rosl.compat.rclpy.*``."""

    def __init__(self) -> None:
        self.force = False

    def find_spec(
        self, fullname: str, path: Any = None, target: types.ModuleType | None = None
    ) -> importlib.machinery.ModuleSpec | None:
        """Return an alias spec for a known name (unless a real module should win)."""
        top, _, rest = fullname.partition(".")
        if top not in ALIASES:
            return None
        if not self.force and not rest:
            real = importlib.machinery.PathFinder.find_spec(fullname, path)
            if real is not None and real.origin not in (None, "namespace"):
                return None
        parent = sys.modules.get(top)
        loader = getattr(parent.__spec__, "loader", None) if parent is not None else None
        if rest and parent is not None and not isinstance(loader, _AliasLoader):
            return None  # a real top-level package: its own submodules
        name = ALIASES[top] + (f".{rest}" if rest else "")
        if importlib.util.find_spec(name) is None:
            return None
        target_spec = importlib.util.find_spec(name)
        is_package = bool(target_spec and target_spec.submodule_search_locations is not None)
        return importlib.machinery.ModuleSpec(fullname, _AliasLoader(name), is_package=is_package)


_finder = AliasFinder()


def install(*, force: bool = False) -> None:
    """Add the alias finder (once); ``force`` makes rosl's modules win over real ones."""
    _finder.force = _finder.force or force
    if force:
        for name in list(sys.modules):
            module = sys.modules[name]
            if name.partition(".")[0] in ALIASES and not isinstance(
                getattr(module.__spec__, "loader", None), _AliasLoader
            ):
                del sys.modules[name]
    if _finder not in sys.meta_path:
        sys.meta_path.insert(0, _finder)
