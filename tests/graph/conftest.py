"""Fixtures for discovery tests: watched children, a fresh observer, and a second domain."""

from __future__ import annotations

import fcntl
import random
import subprocess
from typing import TYPE_CHECKING

import pytest

from tests.conftest import LOCK_DIR
from tests.graph.support import Watched

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from rosl.node.participant import Participant
    from tests.conftest import Processes


@pytest.fixture
def watch(processes: Processes) -> Callable[..., Watched]:
    """Start a Python snippet on the test's domain with its output read line by line."""

    def start(
        code: str, *args: str, env: dict[str, str] | None = None, stdin: int | None = None
    ) -> Watched:
        stdin = subprocess.DEVNULL if stdin is None else stdin
        return Watched(processes.python(code, *args, env=env, stdin=stdin))

    return start


@pytest.fixture
def observer(domain_id: int) -> Iterator[Participant]:
    """A fresh participant (no nodes) on the test's domain: it only listens to discovery."""
    from rosl.node.participant import Participant

    participant = Participant(domain_id)
    try:
        yield participant
    finally:
        participant.close()


@pytest.fixture
def other_domain(domain_id: int) -> Iterator[int]:
    """A second domain id, also locked so no other test uses it meanwhile."""
    LOCK_DIR.mkdir(exist_ok=True)
    candidates = [d for d in range(20, 233) if d != domain_id]
    random.shuffle(candidates)
    for domain in candidates:
        handle = open(LOCK_DIR / f"{domain}.lock", "w")  # noqa: SIM115 - held for the test
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        try:
            yield domain
        finally:
            handle.close()
        return
    pytest.fail("no second free test domain id")
