"""Run the tutorial package's executables as real processes, as ``rosl run`` would."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

import pytest

from tests.conftest import REPO
from tests.graph.support import Watched

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.node import Node
    from tests.conftest import Processes

TUTORIAL_PKG = REPO / "examples" / "tutorial_pkg"


@pytest.fixture(autouse=True, params=["multicast", "zenoh"])
def transport(
    request: pytest.FixtureRequest, processes: Processes, monkeypatch: pytest.MonkeyPatch
) -> str:
    """Every end-to-end test runs on both transports (Zenoh: through its own router)."""
    if request.param == "zenoh":
        from tests.zenoh.conftest import Router

        router = Router(processes)
        monkeypatch.setenv("ROSL_TRANSPORT", "zenoh")
        monkeypatch.setenv("ZENOH_CONFIG_OVERRIDE", router.session_override)
    return str(request.param)


@pytest.fixture
def tutorial(processes: Processes) -> Callable[..., Watched]:
    """Start one tutorial executable (``python -m rosl.pkg.entry``) on the test's domain."""

    def start(executable: str, *args: str) -> Watched:
        command = [
            sys.executable, "-m", "rosl.pkg.entry", str(TUTORIAL_PKG),
            f"tutorial_pkg.{executable}:main", executable, *args,
        ]  # fmt: skip
        return Watched(processes.start(command))

    return start


@pytest.fixture
def observer_node(ros: object) -> Node:
    """A node in the test process, to watch the graph and call services."""
    return ros.Node("e2e_observer")  # type: ignore[attr-defined]
