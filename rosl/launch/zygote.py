"""The launcher's side of the pre-imported interpreter ``rosl launch`` forks its nodes from.

Each ``python -P -m rosl.pkg.entry ...`` node started as a fresh interpreter spends most of
its start-up importing rosl and building the message classes every node uses. The launcher
instead starts one zygote (``zygote_server.py``: single-threaded, its own session, dies with
the launcher) that does that once and then forks one child per node. Each child is still its
own process with the node's environment, working folder, stdin/stdout/stderr, session and
parent-death signal, SIGINT held as ``interrupts`` holds it for a fresh interpreter.

A node is forked only where that is the same as starting it afresh (:func:`can_fork`): rosl's
entry on this interpreter, with the same variables that only take effect when a program
starts (``PYTHON*``, ``LD_*``, locale, allocator); ``TZ`` and the rest are applied in the
child. Whenever the zygote cannot serve (not ready in time, more than one thread, no answer)
the supervisor starts that node, and every later one, afresh; nodes already forked keep
running under the zygote. Their exits reach the launcher before the zygote may reap them (a
pid is never signalled after it could be reused), and should the zygote itself die, the
launcher (a child subreaper) inherits and reaps its nodes, so none is left unsupervised.
:class:`ZygoteProcess` is the part of ``subprocess.Popen`` the supervisor uses.
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
from pathlib import Path
from typing import IO, Any

ENTRY = ("-P", "-m", "rosl.pkg.entry")
SWITCH = "ROSL_LAUNCH_ZYGOTE"  # "0": every node in a fresh interpreter
_PR_SET_PDEATHSIG = 1
_PR_SET_NAME = 15
_PR_SET_CHILD_SUBREAPER = 36
READY_TIMEOUT = 60.0  # its warm-up, on a loaded machine (no node waits on it before it is ready)
ANSWER_TIMEOUT = 10.0  # a warm zygote answers a fork at once
# variables read only when a program starts: a node whose value differs starts afresh
_EXEC_ONLY_PREFIXES = ("PYTHON", "LD_", "LC_", "MALLOC_")
_EXEC_ONLY_NAMES = frozenset({"LANG", "LANGUAGE", "GLIBC_TUNABLES"})


class ZygoteError(OSError):
    """The zygote cannot serve this node (it is then started afresh)."""


def _exec_only(env: dict[str, str]) -> dict[str, str]:
    """The variables that change how an interpreter starts (PYTHONUNBUFFERED aside)."""
    return {
        key: value
        for key, value in env.items()
        if (key.startswith(_EXEC_ONLY_PREFIXES) or key in _EXEC_ONLY_NAMES)
        and key != "PYTHONUNBUFFERED"
    }


def wanted() -> bool:
    """Whether nodes are to be forked (unless ``ROSL_LAUNCH_ZYGOTE=0``)."""
    return os.environ.get(SWITCH, "1") != "0"


def can_fork(cmd: list[str], env: dict[str, str], base: dict[str, str] | None = None) -> bool:
    """Whether a zygote started with ``base`` (default: this environment) can fork ``cmd``.

    That is rosl's entry on this interpreter, with the same start-up-only variables.
    """
    return (
        wanted()
        and len(cmd) > 4
        and cmd[0] == sys.executable
        and tuple(cmd[1:4]) == ENTRY
        and _exec_only(env) == _exec_only(dict(os.environ) if base is None else base)
    )


class Zygote:
    """The launcher's connection to its zygote."""

    def __init__(self) -> None:
        ours, theirs = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
        self.sock = ours
        self.ended = False  # it has closed its end
        self.ready = False  # warmed up
        self.ready_timeout = READY_TIMEOUT
        self.answer_timeout = ANSWER_TIMEOUT
        self.strays: list[int] = []  # forked after the launcher stopped waiting: ended at once
        self._abandoned = 0  # requests not answered in time
        self._buffer = b""
        self._processes: dict[int, ZygoteProcess] = {}
        self.env = {**os.environ, "PYTHONUNBUFFERED": "1"}
        self.popen = subprocess.Popen(
            [sys.executable, *ENTRY[:2], "rosl.launch.zygote_server", str(theirs.fileno())],
            pass_fds=[theirs.fileno()], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, start_new_session=True, env=self.env,
            preexec_fn=die_with_parent,
        )  # fmt: skip
        theirs.close()

    def spawn(self, cmd: list[str], env: dict[str, str], cwd: str | None, hold: bool) -> Any:
        """Fork ``cmd`` (a rosl entry command line); return its :class:`ZygoteProcess`.

        Raises:
            ZygoteError: the zygote is gone, not ready in time, or did not fork (and will not).
        """
        self._wait(lambda: self.ready, self.ready_timeout, "is not ready")
        out_r, out_w = os.pipe()
        err_r, err_w = os.pipe()
        answer: list[str] = []
        try:
            request = {"op": "spawn", "argv": cmd[4:], "env": env, "cwd": cwd, "hold": hold}
            self._send(request, [out_w, err_w])
            self._answers = answer
            try:
                self._wait(lambda: bool(answer), self.answer_timeout, "does not answer")
            except ZygoteError:
                self._abandoned += 1
                raise
            finally:
                self._answers = None
            word, _, rest = answer[0].partition(" ")
            if word != "pid":
                raise ZygoteError(rest)
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

    _answers: list[str] | None = None  # while spawn() waits for its answer

    def _send(self, request: dict[str, Any], fds: list[int] | None = None) -> None:
        try:
            socket.send_fds(self.sock, [json.dumps(request).encode() + b"\n"], fds or [])
        except OSError as err:
            raise ZygoteError(f"the launch zygote has ended ({err.strerror})") from None

    def _wait(self, done: Any, timeout: float, what: str) -> None:
        deadline = time.monotonic() + timeout
        while not done():
            left = deadline - time.monotonic()
            if self.ended:
                raise ZygoteError("the launch zygote has ended")
            if left <= 0:
                raise ZygoteError(f"the launch zygote {what} after {timeout:g} s")
            self.collect(min(left, 1.0))

    def _line(self, timeout: float) -> str | None:
        """The next line from the zygote ('' when none came within ``timeout``; None at EOF)."""
        while b"\n" not in self._buffer:
            if self.sock.fileno() < 0:  # closed by close()
                return None
            ready, _, _ = select.select([self.sock], [], [], timeout)
            if not ready:
                return ""
            try:
                chunk = self.sock.recv(65536)
            except OSError:
                chunk = b""
            if not chunk:
                return None
            self._buffer += chunk
        line, _, self._buffer = self._buffer.partition(b"\n")
        return line.decode()

    def collect(self, timeout: float = 0.0) -> None:
        """Take in what the zygote has said (waiting up to ``timeout`` for its first line)."""
        while not self.ended:
            line = self._line(timeout)
            if line is None:  # gone: its nodes are ours now (subreaper), see ZygoteProcess
                self.ended = True
                return
            if not line:
                return
            timeout = 0.0
            word, _, rest = line.partition(" ")
            if word == "ready":
                self.ready = True
            elif word == "exit":
                self._exited(rest)
            elif self._abandoned:  # answers come in order: first those that came too late
                self._abandoned -= 1
                if word == "pid":
                    self.strays.append(int(rest))
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(int(rest), signal.SIGKILL)  # unreaped until its exit is read
            elif self._answers is not None:
                self._answers.append(line)

    def _exited(self, rest: str) -> None:
        pid_text, _, status = rest.partition(" ")
        pid = int(pid_text)
        process = self._processes.pop(pid, None)
        if process is not None:
            process.returncode = int(status)
        with contextlib.suppress(ZygoteError):
            self._send({"op": "reap", "pid": pid})  # taken in: it may be reaped now

    def close(self) -> None:
        """End the zygote (it ends when its socket closes; nodes left get their death signal)."""
        with contextlib.suppress(OSError):
            self.sock.close()
        with contextlib.suppress(subprocess.TimeoutExpired):
            self.popen.wait(timeout=2)
        if self.popen.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                self.popen.kill()
            with contextlib.suppress(subprocess.TimeoutExpired):
                self.popen.wait(timeout=5)
        for pipe in (self.popen.stdout, self.popen.stderr):
            if pipe is not None:
                pipe.close()


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
        if self.returncode is None and self._zygote.ended:
            self._poll_orphan()
        return self.returncode

    def _poll_orphan(self) -> None:
        """After the zygote's end: the node is this process's child (subreaper), or soon is."""
        try:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
        except ChildProcessError:  # not reparented yet, or no subreaper here
            try:
                os.kill(self.pid, 0)
            except ProcessLookupError:
                self.returncode = -signal.SIGTERM  # its parent-death signal; not ours to reap
            except PermissionError:
                pass
            return
        if pid:
            self.returncode = os.waitstatus_to_exitcode(status)

    def wait(self, timeout: float | None = None) -> int:
        """Wait for the exit.

        Raises:
            subprocess.TimeoutExpired: still running after ``timeout`` seconds.
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.poll() is None:
            left = 0.05 if deadline is None else min(0.05, deadline - time.monotonic())
            if left <= 0:
                raise subprocess.TimeoutExpired(["rosl.pkg.entry"], timeout or 0.0)
            if self._zygote.ended:
                time.sleep(left)
            else:
                self._zygote.collect(left)
        return self.returncode  # type: ignore[return-value]  # set: poll() returned it

    def send_signal(self, signum: int) -> None:
        """Signal the process (unless it has ended: its pid may then be another's)."""
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


def become_subreaper(on: bool = True) -> None:
    """Inherit orphaned descendants (PR_SET_CHILD_SUBREAPER): a lost zygote's nodes.

    ``on`` False: stop (orphans go to init again), once a launch in this process is over.
    """
    if _PRCTL is not None:
        _PRCTL(_PR_SET_CHILD_SUBREAPER, 1 if on else 0)


def reap_orphans() -> list[int]:
    """Reap the ended processes this subreaper inherited from its children's subtrees.

    A process a node or a shell leaves behind (``sh -c 'job &'``) comes to the launcher when
    its parent ends; once it ends it would stay a zombie until the launch does. Reaped here
    are only zombies in a session neither their own nor the launcher's: a node (forked or
    started afresh) leads its own session and is waited for by its supervisor, and what the
    launcher's own code started in its session is that code's to wait for.
    """
    own = os.getsid(0)
    reaped = []
    for pid in _children():
        try:
            fields = Path(f"/proc/{pid}/stat").read_bytes().rsplit(b")", 1)[1].split()
        except (OSError, IndexError):
            continue
        state, session = fields[0], int(fields[3])
        if state != b"Z" or session in (pid, own):
            continue
        with contextlib.suppress(ChildProcessError):
            if os.waitpid(pid, os.WNOHANG)[0] == pid:
                reaped.append(pid)
    return reaped


def _children() -> list[int]:
    """This process's children (of every thread), from /proc (none where it cannot tell)."""
    pids: list[int] = []
    with contextlib.suppress(OSError):
        for task in Path("/proc/self/task").iterdir():
            with contextlib.suppress(OSError):
                pids += [int(word) for word in (task / "children").read_text().split()]
    return pids


def set_name(name: str) -> None:
    """This process's name (``/proc/self/comm``, 15 bytes), as ``top`` and ``pgrep`` show it."""
    if _PRCTL is not None:
        _PRCTL(_PR_SET_NAME, ctypes.c_char_p(name.encode()[:15]))


def die_with_parent() -> None:
    """SIGTERM when the parent dies (PR_SET_PDEATHSIG); safe between fork and exec."""
    if _PRCTL is not None:
        _PRCTL(_PR_SET_PDEATHSIG, signal.SIGTERM)
