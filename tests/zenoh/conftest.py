"""Fixtures for the Zenoh transport: a router on a free loopback port, rosl set to use it."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.conftest import ChildOutput, free_port, wait_until

if TYPE_CHECKING:
    from tests.conftest import Processes

PEER = str(Path(__file__).with_name("peer.py"))


def wait_output(output: ChildOutput, needle: str, timeout: float = 30.0) -> bool:
    """Wait (bounded) until a child printed ``needle`` on stdout."""

    def seen() -> bool:
        output.pump()
        return needle in output.text["out"]

    return wait_until(seen, timeout, interval=0.05)


class Router:
    """A ``rosl zenoh router`` on a free loopback port."""

    def __init__(self, processes: Processes, port: int) -> None:
        self.port = port
        self.endpoint = f"tcp/127.0.0.1:{port}"
        self.child = processes.rosl(
            "zenoh", "router", "--listen", self.endpoint, env={"ZENOH_CONFIG_OVERRIDE": ""}
        )
        self.output = ChildOutput(self.child)
        assert wait_output(self.output, "listening on"), self.output.text

    def peer(self, processes: Processes, role: str, domain: int, *args: str) -> ChildOutput:
        """Start the plain-zenoh rmw_zenoh peer (tests/zenoh/peer.py) in ``role``."""
        child = processes.start([sys.executable, PEER, role, str(self.port), str(domain), *args])
        output = ChildOutput(child)
        assert wait_output(output, "ready"), output.text
        return output


@pytest.fixture
def router(processes: Processes, domain_id: int, monkeypatch: pytest.MonkeyPatch) -> Router:
    """A router; rosl (this process and its children) on Zenoh, connected to it."""
    port = free_port()
    monkeypatch.setenv("ROSL_TRANSPORT", "zenoh")
    monkeypatch.setenv(
        "ZENOH_CONFIG_OVERRIDE",
        f'connect/endpoints=["tcp/127.0.0.1:{port}"];listen/endpoints=["tcp/127.0.0.1:0"]',
    )
    monkeypatch.delenv("ZENOH_SESSION_CONFIG_URI", raising=False)
    monkeypatch.delenv("ZENOH_ROUTER_CONFIG_URI", raising=False)
    return Router(processes, port)


__all__ = ["Router", "free_port", "wait_output", "wait_until"]
