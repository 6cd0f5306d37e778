"""Fixtures for the Zenoh transport: a router on a loopback port, rosl set to use it.

The router binds port 0 and prints the port the system gave it, so no other process can take
the port between its choice and the bind (as with a port probed free, then bound later).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.conftest import ChildOutput, wait_until

if TYPE_CHECKING:
    from tests.conftest import Processes

PEER = str(Path(__file__).with_name("peer.py"))
ROUTER_PORT = re.compile(r"listening on (?:tcp|tls)/127\.0\.0\.1:(\d+)")  # what it was given


def wait_output(output: ChildOutput, needle: str, timeout: float = 30.0) -> bool:
    """Wait (bounded) until a child printed ``needle`` on stdout."""

    def seen() -> bool:
        output.pump()
        return needle in output.text["out"]

    return wait_until(seen, timeout, interval=0.05)


class Router:
    """A ``rosl zenoh router`` on a loopback port the system picks."""

    def __init__(self, processes: Processes) -> None:
        self.child = processes.rosl(
            "zenoh", "router", "--listen", "tcp/127.0.0.1:0", env={"ZENOH_CONFIG_OVERRIDE": ""}
        )
        self.output = ChildOutput(self.child)
        assert wait_output(self.output, "listening on"), self.output.text
        found = ROUTER_PORT.search(self.output.text["out"])
        assert found, self.output.text
        self.port = int(found.group(1))
        self.endpoint = f"tcp/127.0.0.1:{self.port}"

    @property
    def session_override(self) -> str:
        """ZENOH_CONFIG_OVERRIDE for a rosl process connecting to this router only."""
        return f'connect/endpoints=["{self.endpoint}"];listen/endpoints=["tcp/127.0.0.1:0"]'

    def peer(self, processes: Processes, role: str, domain: int, *args: str) -> ChildOutput:
        """Start the plain-zenoh rmw_zenoh peer (tests/zenoh/peer.py) in ``role``."""
        child = processes.start([sys.executable, PEER, role, str(self.port), str(domain), *args])
        output = ChildOutput(child)
        assert wait_output(output, "ready"), output.text
        return output


@pytest.fixture
def router(processes: Processes, domain_id: int, monkeypatch: pytest.MonkeyPatch) -> Router:
    """A router; rosl (this process and its children) on Zenoh, connected to it."""
    monkeypatch.delenv("ZENOH_SESSION_CONFIG_URI", raising=False)
    monkeypatch.delenv("ZENOH_ROUTER_CONFIG_URI", raising=False)
    started = Router(processes)
    monkeypatch.setenv("ROSL_TRANSPORT", "zenoh")
    monkeypatch.setenv("ZENOH_CONFIG_OVERRIDE", started.session_override)
    return started


__all__ = ["ROUTER_PORT", "Router", "wait_output", "wait_until"]
