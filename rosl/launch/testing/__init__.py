"""``import launch_testing`` under rosl: ROS 2's launch tests, for ``rosl launch_test`` and pytest.

The submodules carry launch_testing's names: ``actions`` (ReadyToTest), ``asserts``,
``markers``, ``util``, ``io_handler`` (``proc_output``), ``proc_info_handler`` (``proc_info``);
``loader`` reads a test file, ``test_runner`` runs it on rosl's launch supervisor, ``launch_test``
is ``rosl launch_test``, ``pytest.hooks`` the pytest plugin. Submodules load on first use, so
pytest's start-up (which imports the plugin) stays light. Must not import ``rosl.cli``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any, TypeVar

if TYPE_CHECKING:
    from collections.abc import Callable

T = TypeVar("T")

_SUBMODULES = (
    "actions", "asserts", "io_handler", "junitxml", "launch_test", "loader", "markers",
    "proc_info_handler", "process_proxy", "test_runner", "tools", "util",
)  # fmt: skip
_NOT_IN_ROSL = ("legacy",)


def post_shutdown_test() -> Callable[[T], T]:
    """Mark a ``unittest.TestCase`` class to run after the launched processes have ended."""

    def decorate(cls: T) -> T:
        cls.__post_shutdown_test__ = True  # type: ignore[attr-defined]
        return cls

    return decorate


def ready_to_test_action_timeout(timeout: float) -> Callable[[T], T]:
    """Wait up to ``timeout`` seconds (15 by default) for ReadyToTest before failing the run."""

    def decorate(function: T) -> T:
        function.__ready_to_test_action_timeout__ = float(timeout)  # type: ignore[attr-defined]
        return function

    return decorate


def __getattr__(name: str) -> Any:
    """Load a submodule on first use; name what rosl's launch_testing leaves out."""
    if name == "parametrize":
        from rosl.launch.testing.parametrize import parametrize

        return parametrize
    if name in _SUBMODULES:
        return importlib.import_module(f"{__name__}.{name}")
    if name in _NOT_IN_ROSL:
        from rosl.launch.errors import LaunchError

        raise LaunchError(
            f"'launch_testing.{name}' is not supported by rosl (it provides: actions, asserts, "
            "markers, tools, util, parametrize, post_shutdown_test, "
            "ready_to_test_action_timeout)"
        )
    raise AttributeError(f"module 'launch_testing' has no attribute '{name}'")


__all__ = ["post_shutdown_test", "ready_to_test_action_timeout"]
