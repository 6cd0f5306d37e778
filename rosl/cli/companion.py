"""A rosl command run beside another for its whole life (``launch --bridge``, ``sim --serve``).

The companion is a child process (``python -m rosl ARGS``) on the same domain: it has its own
participant and signal handling, so it cannot slow down or confuse the main command, and it
ends (Ctrl-C, then a kill) by its pid when the main command returns, also on failure.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import threading
from typing import TYPE_CHECKING, Any, TypeVar

import click

from rosl.errors import RoslError

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

STOP_S = 5.0
F = TypeVar("F", bound="Callable[..., Any]")


def companion_options(command: F) -> F:
    """``--serve [--serve-port]`` and ``--bridge [--bridge-port]`` for a long-running command."""
    for option in reversed((
        click.option("--serve", is_flag=True,
                     help="Also serve the live world in a browser page (rosl viz --serve)"),
        click.option("--serve-port", type=int, default=8080, show_default=True,
                     help="The page's port (--serve)"),
        click.option("--bridge", is_flag=True,
                     help="Also run a Foxglove WebSocket server (rosl bridge foxglove)"),
        click.option("--bridge-port", type=int, default=8765, show_default=True,
                     help="The Foxglove server's port (--bridge)"),
    )):  # fmt: skip
        command = option(command)
    return command


class CompanionError(RoslError):
    """The companion command did not start."""


@contextlib.contextmanager
def companion(
    args: list[str], domain: int | None, ready: str, ready_s: float = 60.0
) -> Iterator[None]:
    """Run ``rosl ARGS`` beside the body; its output goes to stderr, prefixed with its name.

    The body starts once the companion printed a line containing ``ready``.

    Raises:
        CompanionError: it exited, or said nothing ready within ``ready_s`` (its last line
            says why).
    """
    env = dict(os.environ)
    if domain is not None:
        env["ROSL_DOMAIN_ID"] = str(domain)
    child = subprocess.Popen(
        [sys.executable, "-m", "rosl", *args],
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # the terminal's Ctrl-C is ours to pass on, once
    )
    name = " ".join(args[:2])
    started = threading.Event()
    lines: list[str] = []
    up: list[bool] = []  # [True] once the ready line came

    def relay() -> None:
        assert child.stdout is not None
        for line in child.stdout:
            lines.append(line.rstrip("\n"))
            print(f"[{name}] {line.rstrip()}", file=sys.stderr, flush=True)
            if ready in line and not up:
                up.append(True)
                started.set()
        started.set()  # its output ended: it is not (or no longer) running

    threading.Thread(target=relay, name="rosl-companion", daemon=True).start()
    try:
        if not started.wait(ready_s) or not up or child.poll() is not None:
            said = lines[-1] if lines else f"exit code {child.poll()}"
            raise CompanionError(f"`rosl {' '.join(args)}` did not start: {said}")
        yield
    finally:
        _stop(child)


@contextlib.contextmanager
def companions(*, serve: int | None, bridge: int | None, domain: int | None) -> Iterator[None]:
    """``--serve`` (the live page) and ``--bridge`` (Foxglove) beside a command, on these ports.

    Raises:
        CompanionError: a companion did not start (e.g. its port is in use).
    """
    with contextlib.ExitStack() as stack:
        if bridge is not None:
            args = ["bridge", "foxglove", "--port", str(bridge)]
            stack.enter_context(companion(args, domain, ready="listening on"))
        if serve is not None:
            args = ["viz", "--serve", "--port", str(serve)]
            stack.enter_context(companion(args, domain, ready="live view at"))
        yield


def _stop(child: subprocess.Popen[str]) -> None:
    if child.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            child.send_signal(signal.SIGINT)
        try:
            child.wait(STOP_S)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait(STOP_S)
