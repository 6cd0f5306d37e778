"""A pre-imported interpreter that ``rosl launch`` forks its Python nodes from.

Each ``python -P -m rosl.pkg.entry ...`` node started as a fresh interpreter spends most of
its start-up importing rosl, numpy and rosbags and building the message classes every node
uses; ten at once on two cores take over a second. The launcher instead starts one zygote
(``python -P -m rosl.launch.zygote FD``, single-threaded, its own session) that imports all
that once and then forks one child per node. Each child is still its own process with the
node's environment, working folder, stdin/stdout/stderr, session (process group) and
parent-death signal, SIGINT held as ``interrupts`` holds it for a fresh interpreter, and it
runs ``rosl.pkg.entry`` and exits through the interpreter's normal exit (atexit handlers, non-
daemon threads joined).

Protocol over a Unix socket pair: the launcher sends one JSON request ``{argv, env, cwd,
hold}`` with the child's stdout and stderr descriptors attached; the zygote answers ``pid N``
(or ``error TEXT``), and later ``exit N STATUS`` when it has reaped that child.
:class:`ZygoteProcess` is the launcher's side: the part of ``subprocess.Popen`` the
supervisor uses (pid, stdout, stderr, poll, wait, send_signal, returncode).
"""

from __future__ import annotations

import contextlib
import ctypes
import json
import os
import select
import signal
import socket
import subprocess
import sys
import time
from typing import IO, Any

ENTRY = ("-P", "-m", "rosl.pkg.entry")
SWITCH = "ROSL_LAUNCH_ZYGOTE"  # "1": fork nodes from a pre-imported interpreter (opt-in)
_PR_SET_PDEATHSIG = 1
ANSWER_TIMEOUT = 60.0  # its warm-up included, on a loaded machine
_WARM_TYPES = (  # what every node builds at start (parameters, events, rosout, services)
    "rcl_interfaces/msg/ParameterEvent",
    "rcl_interfaces/msg/Log",
    "rcl_interfaces/msg/SetParametersResult",
    "std_msgs/msg/String",
)


def _python_env(env: dict[str, str]) -> dict[str, str]:
    """The variables that change how an interpreter starts (PYTHONUNBUFFERED aside)."""
    return {k: v for k, v in env.items() if k.startswith("PYTHON") and k != "PYTHONUNBUFFERED"}


def wanted() -> bool:
    """Whether nodes are to be forked (only with ``ROSL_LAUNCH_ZYGOTE=1``: opt-in for now)."""
    return os.environ.get(SWITCH) == "1"


def can_fork(cmd: list[str], env: dict[str, str], base: dict[str, str] | None = None) -> bool:
    """Whether a zygote started with ``base`` (default: this environment) can fork ``cmd``.

    That is rosl's entry on this interpreter, with the same PYTHON* variables.
    """
    return (
        wanted()
        and len(cmd) > 4
        and cmd[0] == sys.executable
        and tuple(cmd[1:4]) == ENTRY
        and _python_env(env) == _python_env(dict(os.environ) if base is None else base)
    )


# --- the launcher's side ------------------------------------------------------------------------


class Zygote:
    """The launcher's connection to its zygote (started on first use)."""

    def __init__(self) -> None:
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        self.sock = ours
        self.ended = False  # it has closed its end (and its children are gone with it)
        self._buffer = b""
        self._processes: dict[int, ZygoteProcess] = {}
        self.env = {**os.environ, "PYTHONUNBUFFERED": "1"}
        self.popen = subprocess.Popen(
            [sys.executable, *ENTRY[:2], "rosl.launch.zygote", str(theirs.fileno())],
            pass_fds=[theirs.fileno()], stdin=subprocess.DEVNULL, start_new_session=True,
            env=self.env, preexec_fn=die_with_parent,
        )  # fmt: skip
        theirs.close()

    def spawn(self, cmd: list[str], env: dict[str, str], cwd: str | None, hold: bool) -> Any:
        """Fork ``cmd`` (a rosl entry command line); return its :class:`ZygoteProcess`.

        Raises:
            OSError: the zygote is gone or could not fork.
        """
        out_r, out_w = os.pipe()
        err_r, err_w = os.pipe()
        try:
            request = {"argv": cmd[4:], "env": env, "cwd": cwd, "hold": hold}
            socket.send_fds(self.sock, [json.dumps(request).encode() + b"\n"], [out_w, err_w])
            while True:
                line = self._line(ANSWER_TIMEOUT)
                if line is None:
                    raise OSError("the launch zygote has ended")
                if not line:
                    raise OSError("the launch zygote does not answer")
                word, _, rest = line.partition(" ")
                if word == "pid":
                    break
                if word == "error":
                    raise OSError(rest)
                self._exited(rest)
        except BaseException:
            os.close(out_r)
            os.close(err_r)
            raise
        finally:
            os.close(out_w)
            os.close(err_w)
        process = ZygoteProcess(self, int(rest), os.fdopen(out_r, "rb"), os.fdopen(err_r, "rb"))
        self._processes[process.pid] = process
        return process

    def _line(self, timeout: float | None) -> str | None:
        """The next line from the zygote ('' when none came within ``timeout``; None at EOF)."""
        while b"\n" not in self._buffer:
            if self.sock.fileno() < 0:  # closed by close()
                return None
            ready, _, _ = select.select([self.sock], [], [], timeout)
            if not ready:
                return ""
            chunk = self.sock.recv(65536)
            if not chunk:
                return None
            self._buffer += chunk
        line, _, self._buffer = self._buffer.partition(b"\n")
        return line.decode()

    def _exited(self, rest: str) -> None:
        pid, _, status = rest.partition(" ")
        process = self._processes.pop(int(pid), None)
        if process is not None:
            process.returncode = int(status)

    def collect(self, timeout: float = 0.0) -> None:
        """Take in the exits the zygote has reported (waiting up to ``timeout`` for one)."""
        while True:
            line = self._line(timeout)
            if line is None:  # the zygote is gone: so are its children (parent-death signal)
                self.ended = True
                for process in self._processes.values():
                    process.returncode = -signal.SIGKILL
                self._processes.clear()
                return
            if not line:
                return
            word, _, rest = line.partition(" ")
            if word == "exit":
                self._exited(rest)
                timeout = 0.0

    def close(self) -> None:
        """End the zygote (its children, if any are left, get their parent-death signal)."""
        with contextlib.suppress(OSError):
            self.sock.close()
        if self.popen.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                self.popen.kill()
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.popen.wait(timeout=5)


class ZygoteProcess:
    """A node forked by the zygote, seen through the part of ``Popen`` the supervisor uses."""

    def __init__(self, zygote: Zygote, pid: int, stdout: IO[bytes], stderr: IO[bytes]) -> None:
        self._zygote = zygote
        self.pid = pid
        self.stdout: IO[bytes] | None = stdout
        self.stderr: IO[bytes] | None = stderr
        self.returncode: int | None = None

    def poll(self) -> int | None:
        """The exit code (negative: the signal), or None while it runs."""
        if self.returncode is None:
            self._zygote.collect()
        return self.returncode

    def wait(self, timeout: float | None = None) -> int:
        """Wait for the exit.

        Raises:
            subprocess.TimeoutExpired: still running after ``timeout`` seconds.
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.returncode is None:
            left = 1.0 if deadline is None else deadline - time.monotonic()
            if left <= 0:
                raise subprocess.TimeoutExpired(["rosl.pkg.entry"], timeout or 0.0)
            self._zygote.collect(min(left, 1.0))
        return self.returncode

    def send_signal(self, signum: int) -> None:
        """Signal the process (unless it has ended)."""
        if self.poll() is None:
            os.kill(self.pid, signum)

    def kill(self) -> None:
        """SIGKILL the process."""
        self.send_signal(signal.SIGKILL)


def _libc_prctl() -> Any:
    try:
        return ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None


_PRCTL = _libc_prctl()  # looked up here: a forked child (maybe of a threaded parent) only calls


def die_with_parent() -> None:
    """SIGTERM when the parent dies (PR_SET_PDEATHSIG); safe between fork and exec."""
    if _PRCTL is not None:
        _PRCTL(_PR_SET_PDEATHSIG, signal.SIGTERM)


# --- the zygote's side --------------------------------------------------------------------------


def _warm() -> None:
    """Import what a node imports and build the message classes every node builds."""
    import numpy  # noqa: F401
    import yaml  # noqa: F401

    import rosl
    import rosl.executor
    import rosl.node.node
    import rosl.node.participant
    import rosl.pkg.entry
    import rosl.runtime
    from rosl.idl.registry import get_message_class

    rosl.compat.install(force=True)
    for name in _WARM_TYPES:
        with contextlib.suppress(Exception):  # a broken search path: the node will say so
            get_message_class(name)


def serve(sock: socket.socket) -> list[str] | None:
    """Fork a child per request; in the child return its entry argv, in the zygote None at EOF."""
    wake_r, wake_w = os.pipe()
    os.set_blocking(wake_w, False)
    signal.set_wakeup_fd(wake_w)
    signal.signal(signal.SIGCHLD, lambda *_: None)
    buffer = b""
    fds: list[int] = []
    while True:
        _reap(sock)
        try:
            ready, _, _ = select.select([sock.fileno(), wake_r], [], [])
        except InterruptedError:
            continue
        if wake_r in ready:
            os.read(wake_r, 4096)
        if sock.fileno() not in ready:
            continue
        data, received, _, _ = socket.recv_fds(sock, 1 << 20, 2)
        if not data:
            return None
        buffer += data
        fds += received
        if b"\n" not in buffer:
            continue  # the rest of the request follows
        line, _, buffer = buffer.partition(b"\n")
        request = json.loads(line)
        try:
            pid = os.fork()
        except OSError as err:
            sock.sendall(f"error cannot fork: {err.strerror}\n".encode())
            fds = _closed(fds)
            continue
        if pid == 0:
            signal.set_wakeup_fd(-1)
            signal.signal(signal.SIGCHLD, signal.SIG_DFL)
            for fd in (wake_r, wake_w):
                os.close(fd)
            sock.close()
            _become_child(request, fds)
            return list(request["argv"])
        fds = _closed(fds)
        sock.sendall(f"pid {pid}\n".encode())


def _closed(fds: list[int]) -> list[int]:
    for fd in fds:
        os.close(fd)
    return []


def _reap(sock: socket.socket) -> None:
    while True:
        try:
            pid, status = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        sock.sendall(f"exit {pid} {os.waitstatus_to_exitcode(status)}\n".encode())


def _become_child(request: dict[str, Any], fds: list[int]) -> None:
    """Turn this fork into the node's process, as Popen and ``prepare_child`` would have."""
    os.setsid()
    die_with_parent()
    null = os.open(os.devnull, os.O_RDONLY)
    os.dup2(null, 0)
    os.close(null)
    os.dup2(fds[0], 1)
    os.dup2(fds[1], 2)
    for fd in fds:
        os.close(fd)
    if request["cwd"]:
        os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    if request["hold"]:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    signal.signal(signal.SIGINT, signal.default_int_handler)  # as a fresh interpreter has it


def main(argv: list[str]) -> int:
    """The zygote: warm up, then serve the launcher until it closes the socket."""
    sock = socket.socket(fileno=int(argv[0]))
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the launcher ends it (by closing, or SIGKILL)
    _warm()
    child = serve(sock)
    if child is None:
        return 0
    from rosl.pkg import entry

    sys.argv = [entry.__file__, *child]  # as `python -m rosl.pkg.entry ...` has it
    return entry.main(child)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
