"""A real browser for the live view's tests: Debian's chromium, headless, installed where missing.

``chromium`` (session-scoped) gives /usr/bin/chromium, installing it with apt-get when it is
absent and this process may (root, apt-get present); otherwise the test is skipped with the
reason. :class:`Browser` drives one headless chromium over the DevTools protocol on a pipe
(``--remote-debugging-pipe``: fds 3 and 4, no port, no WebSocket), so a test can wait, in real
time and bounded, for what a page shows. :func:`run_chromium` runs one-shot ``--dump-dom`` /
``--screenshot`` commands. Every chromium started here is ended by its pid (its process group).
"""

from __future__ import annotations

import base64
import contextlib
import json
import os
import select
import signal
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest

from tests.debian import install

CHROMIUM = Path("/usr/bin/chromium")
# the machine's network is closed: without these chromium waits on connections it tries to make
FLAGS = (
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-dev-shm-usage", "--hide-scrollbars",
)  # fmt: skip


def install_chromium() -> str | None:
    """Install chromium with apt-get; the reason it cannot be, or None once it is there."""
    return install(["chromium"], [str(CHROMIUM)])


@pytest.fixture(scope="session")
def chromium() -> Path:
    """Debian's chromium (installed by apt-get where missing), or a skip saying why not."""
    reason = install_chromium()
    if reason is not None:
        pytest.skip(reason)
    return CHROMIUM


def end_group(child: subprocess.Popen[Any], timeout: float = 10.0) -> None:
    """Wait for ``child`` (bounded), then SIGKILL its process group (its pid) if anything is left."""
    with contextlib.suppress(subprocess.TimeoutExpired):
        child.wait(timeout=timeout)
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(child.pid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        child.wait(timeout=10)


def run_chromium(binary: Path, profile: Path, args: list[str], timeout: float = 60.0) -> str:
    """Run one headless chromium command (``--dump-dom URL``...) to the end; its stdout."""
    log = profile.with_suffix(".log")
    with log.open("w") as err:
        child = subprocess.Popen(
            [str(binary), *FLAGS, f"--user-data-dir={profile}", *args],
            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=err, text=True,
            start_new_session=True,
        )  # fmt: skip
        try:
            out, _ = child.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            end_group(child, timeout=0)
            raise AssertionError(f"chromium did not finish within {timeout} s: {args}") from None
        finally:
            end_group(child, timeout=0)
    assert child.returncode == 0, f"chromium exited with {child.returncode}; see {log}"
    return out


class Browser:
    """One headless chromium with one page, driven over DevTools on a pipe."""

    def __init__(self, binary: Path, profile: Path, size: tuple[int, int] = (1000, 900)) -> None:
        commands_r, self._commands = os.pipe()  # chromium reads its commands on fd 3
        self._replies, replies_w = os.pipe()  # and writes its replies and events on fd 4
        argv = [
            str(binary), *FLAGS, f"--user-data-dir={profile}", "--remote-debugging-pipe",
            f"--window-size={size[0]},{size[1]}", "about:blank",
        ]  # fmt: skip
        script = f'exec "$0" "$@" 3<&{commands_r} 4>&{replies_w} {commands_r}<&- {replies_w}>&-'
        self.log = profile.with_suffix(".log")
        with self.log.open("w") as err:
            self.child = subprocess.Popen(
                ["/bin/bash", "-c", script, *argv], pass_fds=(commands_r, replies_w),
                stdin=subprocess.DEVNULL, stdout=err, stderr=err, start_new_session=True,
            )  # fmt: skip
        os.close(commands_r)
        os.close(replies_w)
        self._buffer = b""
        self._next_id = 0
        self.exceptions: list[str] = []  # uncaught script errors and console.error calls
        self.size = size
        self.session = ""

    def call(
        self, method: str, params: dict[str, Any] | None = None, timeout: float = 30.0
    ) -> dict[str, Any]:
        """Send one command (to the page once :meth:`open` attached) and return its result."""
        self._next_id += 1
        message: dict[str, Any] = {"id": self._next_id, "method": method, "params": params or {}}
        if self.session and not method.startswith(("Target.", "Browser.")):
            message["sessionId"] = self.session
        data = json.dumps(message).encode() + b"\0"
        while data:
            data = data[os.write(self._commands, data) :]
        deadline = time.monotonic() + timeout
        while True:
            while b"\0" in self._buffer:
                raw, self._buffer = self._buffer.split(b"\0", 1)
                reply = json.loads(raw)
                if reply.get("id") == self._next_id:
                    assert "error" not in reply, f"{method}: {reply['error']}"
                    return dict(reply.get("result", {}))
                self._event(reply)
            left = deadline - time.monotonic()
            assert left > 0, f"chromium did not answer {method} within {timeout} s"
            ready, _, _ = select.select([self._replies], [], [], left)
            if ready:
                chunk = os.read(self._replies, 1 << 20)
                assert chunk, f"chromium closed its DevTools pipe; see {self.log}"
                self._buffer += chunk

    def _event(self, event: dict[str, Any]) -> None:
        params = event.get("params", {})
        if event.get("method") == "Runtime.exceptionThrown":
            details = params.get("exceptionDetails", {})
            self.exceptions.append(str(details.get("exception", {}).get("description", details)))
        elif event.get("method") == "Runtime.consoleAPICalled" and params.get("type") == "error":
            self.exceptions.append(" ".join(str(a.get("value")) for a in params.get("args", [])))

    def open(self, url: str) -> None:
        """Open ``url`` in a new page, watching its script errors."""
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        attached = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})
        self.session = attached["sessionId"]
        self.call("Runtime.enable")
        self.call("Page.enable")
        width, height = self.size
        self.call(
            "Emulation.setDeviceMetricsOverride",
            {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
        )
        self.call("Page.navigate", {"url": url})

    def evaluate(self, expression: str) -> Any:
        """The value of a JavaScript expression in the page."""
        result = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True})
        assert "exceptionDetails" not in result, result["exceptionDetails"]
        return result["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 30.0) -> Any:
        """Evaluate until the value is truthy (bounded); that value, or the last one."""
        deadline = time.monotonic() + timeout
        while not (value := self.evaluate(expression)) and time.monotonic() < deadline:
            time.sleep(0.2)
        return value

    def screenshot(self, path: Path) -> Path:
        """Save what the page shows now as a PNG."""
        data = self.call("Page.captureScreenshot", {"format": "png"})["data"]
        path.write_bytes(base64.b64decode(data))
        return path

    def close(self) -> None:
        """Ask chromium to quit, then end what is left of it by its pid."""
        with contextlib.suppress(AssertionError, OSError):
            self.call("Browser.close", timeout=10)
        end_group(self.child)
        for fd in (self._commands, self._replies):
            with contextlib.suppress(OSError):
                os.close(fd)


@pytest.fixture
def browser(chromium: Path, tmp_path: Path) -> Any:
    """A headless chromium with a fresh profile, ended by pid after the test."""
    opened = Browser(chromium, tmp_path / "chromium-profile")
    try:
        yield opened
    finally:
        opened.close()
