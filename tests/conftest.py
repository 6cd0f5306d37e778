"""Fixtures shared by every test: an isolated search path and helpers to write packages."""

from __future__ import annotations

import codecs
import contextlib
import fcntl
import os
import random
import select
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import IO, TYPE_CHECKING

import pytest

from rosl.idl import registry, search_path

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

REPO = Path(__file__).resolve().parent.parent


# the slowest modules, started first so the parallel workers do not end waiting on one of them
FIRST = ("tests/test_lint.py", "tests/test_packaging.py")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Run the slowest modules first (the order is otherwise the files' order)."""

    def rank(item: pytest.Item) -> int:
        path = item.path.relative_to(REPO).as_posix() if REPO in item.path.parents else ""
        return FIRST.index(path) if path in FIRST else len(FIRST)

    items.sort(key=rank)  # stable: each module keeps its order


@pytest.fixture(autouse=True)
def isolated_search_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """Run each test from an empty folder, with no ROSL_PACKAGE_PATH and fresh caches."""
    home = tmp_path / "cwd"
    home.mkdir()
    monkeypatch.chdir(home)
    monkeypatch.delenv("ROSL_PACKAGE_PATH", raising=False)
    registry.clear()
    yield
    registry.clear()


def write_package(
    root: Path, name: str, files: dict[str, str] | None = None, manifest: str | None = None
) -> Path:
    """Write a package folder ``root/name`` with a package.xml and the given files."""
    folder = root / name
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(
        manifest
        if manifest is not None
        else f'<?xml version="1.0"?>\n<package format="3">\n  <name>{name}</name>\n'
        "  <version>0.0.0</version>\n</package>\n"
    )
    for relative, text in (files or {}).items():
        path = folder / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return folder


@pytest.fixture
def workspace(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A ROS-style workspace (``ws/src``) that is the current directory."""
    ws = tmp_path / "ws"
    (ws / "src").mkdir(parents=True)
    monkeypatch.chdir(ws)
    search_path.rescan()
    return ws


@pytest.fixture
def make_package(workspace: Path) -> Callable[..., Path]:
    """Write a package into the workspace's src/ and drop cached scans."""

    def make(name: str, files: dict[str, str] | None = None, manifest: str | None = None) -> Path:
        folder = write_package(workspace / "src", name, files, manifest)
        registry.clear()
        return folder

    return make


# --- the bus: one domain per test, processes ended by pid --------------------------------------

LOCK_DIR = Path("/tmp/rosl-test-domains")


def lock_domain() -> tuple[int, IO[str]]:
    """A domain id no other test on this machine uses, and the open lock file holding it."""
    LOCK_DIR.mkdir(exist_ok=True)
    candidates = list(range(20, 233))
    random.shuffle(candidates)
    for domain in candidates:
        handle = open(LOCK_DIR / f"{domain}.lock", "w")  # noqa: SIM115 - held by the caller
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        return domain, handle
    pytest.fail("no free test domain id")


# --- TCP ports: below the kernel's ephemeral range, each locked by a file --------------------

PORT_LOCK_DIR = Path("/tmp/rosl-test-ports")
PORTS = range(20000, 30000)  # the ephemeral range (Linux: 32768-60999) never hands these out
_held_ports: list[IO[str]] = []  # locks kept for the life of this process (a pytest worker)


def free_port() -> int:
    """A TCP port of 127.0.0.1 that nobody listens on and no other test (worker) gets.

    A port the kernel picks for ``bind(0)`` may be picked again for another socket as soon as
    the probe closes; one from a fixed range, locked by a file, is this test's alone.
    """
    PORT_LOCK_DIR.mkdir(exist_ok=True)
    candidates = list(PORTS)
    random.shuffle(candidates)
    for port in candidates:
        handle = open(PORT_LOCK_DIR / f"{port}.lock", "w")  # noqa: SIM115 - held until exit
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        with socket.socket() as probe:
            try:
                probe.bind(("127.0.0.1", port))
            except OSError:
                handle.close()
                continue
        _held_ports.append(handle)
        return port
    pytest.fail("no free test TCP port")


@pytest.fixture
def domain_id(monkeypatch: pytest.MonkeyPatch) -> Iterator[int]:
    """A domain id no other test on this machine uses right now (locked by a file)."""
    domain, handle = lock_domain()
    monkeypatch.setenv("ROSL_DOMAIN_ID", str(domain))
    monkeypatch.delenv("ROS_DOMAIN_ID", raising=False)
    try:
        yield domain
    finally:
        handle.close()


class Processes:
    """Starts child processes for a test and ends every one of them, by pid, afterwards."""

    def __init__(self) -> None:
        self.started: list[subprocess.Popen[str]] = []

    def start(
        self,
        args: list[str],
        *,
        cwd: Path | None = None,
        env: dict[str, str] | None = None,
        stdin: int | None = subprocess.DEVNULL,
    ) -> subprocess.Popen[str]:
        full_env = {**os.environ, "PYTHONUNBUFFERED": "1", **(env or {})}
        child = subprocess.Popen(
            args,
            cwd=cwd,
            env=full_env,
            stdin=stdin,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            start_new_session=True,
        )
        self.started.append(child)
        return child

    def python(self, code: str, *args: str, **kwargs: object) -> subprocess.Popen[str]:
        """Run a Python snippet (rosl imported by the snippet itself)."""
        return self.start([sys.executable, "-c", code, *args], **kwargs)  # type: ignore[arg-type]

    def rosl(self, *args: str, **kwargs: object) -> subprocess.Popen[str]:
        """Run the rosl command line."""
        return self.start([sys.executable, "-m", "rosl", *args], **kwargs)  # type: ignore[arg-type]

    @staticmethod
    def stop(child: subprocess.Popen[str], timeout: float = 5.0) -> tuple[str, str]:
        """Ctrl-C a child, then SIGKILL if it does not exit; return its output."""
        if child.poll() is None:
            child.send_signal(signal.SIGINT)
        try:
            out, err = child.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            child.kill()
            out, err = child.communicate(timeout=5)
        return out, err

    def close(self) -> None:
        for child in self.started:
            if child.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(child.pid, signal.SIGKILL)
                child.kill()
            with contextlib.suppress(subprocess.TimeoutExpired, ValueError):
                child.communicate(timeout=5)


@pytest.fixture
def processes(domain_id: int) -> Iterator[Processes]:
    """Child processes on this test's domain, all ended (by pid) when the test finishes."""
    group = Processes()
    try:
        yield group
    finally:
        group.close()


def wait_until(
    predicate: Callable[[], bool], timeout: float = 15.0, interval: float = 0.02
) -> bool:
    """Poll ``predicate`` until true or the (bounded) timeout."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(interval)
    return predicate()


@pytest.fixture
def ros(domain_id: int) -> Iterator[object]:
    """rosl initialized in the test process on the test's domain; shut down afterwards."""
    import rosl

    rosl.init([])
    try:
        yield rosl
    finally:
        rosl.shutdown()


class ChildOutput:
    """A child's stdout/stderr read without blocking, always with a deadline (``text``)."""

    def __init__(self, popen: subprocess.Popen[str]) -> None:
        self.popen = popen
        assert popen.stdout is not None
        assert popen.stderr is not None
        self._fds = {popen.stdout.fileno(): "out", popen.stderr.fileno(): "err"}
        self._open = set(self._fds)
        self._decoders = {
            s: codecs.getincrementaldecoder("utf-8")("replace") for s in ("out", "err")
        }
        self.text = {"out": "", "err": ""}

    def _read(self, timeout: float) -> None:
        if not self._open:
            time.sleep(min(timeout, 0.02))
            return
        ready, _, _ = select.select(list(self._open), [], [], max(0.0, timeout))
        for fd in ready:
            chunk = os.read(fd, 65536)
            stream = self._fds[fd]
            if chunk:
                self.text[stream] += self._decoders[stream].decode(chunk)
            else:
                self._open.discard(fd)

    def pump(self) -> None:
        """Read whatever the child has printed so far (no waiting)."""
        self._read(0.0)
