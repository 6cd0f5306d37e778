"""Fixtures of the node tests: ``spawn`` starts a child on the test's domain and reads it."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

import pytest

from tests.node.helpers import Child, snippet

if TYPE_CHECKING:
    from collections.abc import Callable

    from tests.conftest import Processes


@pytest.fixture(autouse=True)
def fresh_interface_classes(isolated_search_path: None) -> None:
    """Forget message classes cached on ``std_msgs.msg``-style modules by earlier tests.

    The root conftest clears rosl's registry before each test; a class cached on the import
    module would belong to the previous registry's serializers.
    """
    from rosl.compat.interfaces import InterfaceModule

    for module in list(sys.modules.values()):
        if isinstance(module, InterfaceModule):
            for attr in [a for a in vars(module) if not a.startswith("__")]:
                delattr(module, attr)


@pytest.fixture(autouse=True)
def plain_console(monkeypatch: pytest.MonkeyPatch) -> None:
    """Children log with rcutils' default format, on stderr, without colour."""
    for name in (
        "RCUTILS_CONSOLE_OUTPUT_FORMAT",
        "RCUTILS_LOGGING_USE_STDOUT",
        "RCUTILS_COLORIZED_OUTPUT",
    ):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("NO_COLOR", "1")


class Spawner:
    """Start children (ended by pid by the ``processes`` fixture) and wrap them in Child."""

    def __init__(self, processes: Processes) -> None:
        self.processes = processes

    def __call__(self, code: str, *args: str, **kwargs: Any) -> Child:
        """Run a Python snippet with ``args`` as its command line."""
        return Child(self.processes.python(snippet(code), *args, **kwargs), self.processes)

    def command(self, args: list[str], **kwargs: Any) -> Child:
        """Run any command."""
        return Child(self.processes.start(args, **kwargs), self.processes)

    def module(self, module: str, *args: str, **kwargs: Any) -> Child:
        """Run ``python -m module args``."""
        return self.command([sys.executable, "-m", module, *args], **kwargs)


@pytest.fixture
def spawn(processes: Processes) -> Callable[..., Child]:
    """Start a child Python snippet on the test's domain: ``spawn(code, *argv)``."""
    return Spawner(processes)
