"""The zygote itself: a pre-imported interpreter that forks one child per rosl node.

Started by the launcher (``zygote.py``) as ``python -P -m rosl.launch.zygote_server FD``, in
its own session, its stdout and stderr piped to the launcher (which prefixes them). It imports
what a node imports and builds what every node builds (no numpy, nothing that starts a
thread), says ``ready``, then serves JSON lines on the socket FD:

* ``{"op": "spawn", argv, env, cwd, hold}`` with the child's stdout and stderr descriptors
  attached: answered ``pid N``, or ``error TEXT`` when it cannot fork safely — a fork is only
  made while this process has exactly one thread (native ones counted, from /proc);
* ``{"op": "reap", "pid": N}``: the launcher has taken in N's exit, N may now be reaped.

A child's exit is reported as ``exit N STATUS`` as soon as it happens, but the child stays a
zombie until the launcher's ``reap``, so its pid (and process group) cannot be reused while
the launcher may still signal it. EOF on the socket ends the zygote.
"""

from __future__ import annotations

import contextlib
import json
import os
import select
import signal
import socket
import sys
import time
from typing import Any

from rosl.launch.zygote import ENTRY, die_with_parent, set_name

_WARM_MODULES = (  # what a node imports (measured: the modules new after rosl.Node(...))
    "yaml",
    "rosl",
    "rosl.bus.multicast",
    "rosl.bus.pacing",
    "rosl.executor",
    "rosl.node.guard_condition",
    "rosl.node.lockstep",
    "rosl.node.node",
    "rosl.node.parameter_services",
    "rosl.node.participant",
    "rosl.node.publisher",
    "rosl.node.qos_compatibility",
    "rosl.node.qos_events",
    "rosl.node.qos_overrides",
    "rosl.node.qos_watch",
    "rosl.node.service",
    "rosl.node.subscription",
    "rosl.node.timer",
    "rosl.pkg.entry",
    "rosl.runtime",
)
_WARM_TYPES = (  # the messages every node sends: parameter events, rosout
    "rcl_interfaces/msg/ParameterEvent",
    "rcl_interfaces/msg/Log",
    "std_msgs/msg/String",
)
_WARM_SERVICES = (  # the parameter services every node serves
    "rcl_interfaces/srv/DescribeParameters",
    "rcl_interfaces/srv/GetParameterTypes",
    "rcl_interfaces/srv/GetParameters",
    "rcl_interfaces/srv/ListParameters",
    "rcl_interfaces/srv/SetParameters",
    "rcl_interfaces/srv/SetParametersAtomically",
)


def _warm() -> None:
    """Import what a node imports; build (and serialize once) the messages every node sends."""
    import importlib

    for name in _WARM_MODULES:
        importlib.import_module(name)
    from rosl.compat import install
    from rosl.idl.registry import get_message_class, get_service_class, store

    install(force=True)
    for name in _WARM_TYPES:
        with contextlib.suppress(Exception):  # a broken search path: the node will say so
            store().serialize(get_message_class(name)())  # class and serializer made once
    for name in _WARM_SERVICES:
        with contextlib.suppress(Exception):
            service = get_service_class(name)
            for message in (service.Request(), service.Response()):
                store().serialize(message)  # not decoded: an array would load numpy (threads)


def threads() -> int:
    """This process's threads, native ones included (a library's pool is not seen by Python)."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        import threading

        return threading.active_count()


class _Server:
    """The zygote's loop: requests in, forks and exit reports out."""

    def __init__(self, sock: socket.socket) -> None:
        self.sock = sock
        self.running: set[int] = set()  # forked, exit not yet reported
        self.reported: set[int] = set()  # exit reported, reap not yet allowed
        self.buffer = b""
        self.fds: list[int] = []

    def serve(self) -> dict[str, Any] | None:
        """Serve until EOF (None); in a forked child, return its request."""
        wake_r, wake_w = os.pipe()
        os.set_blocking(wake_w, False)
        signal.set_wakeup_fd(wake_w)
        signal.signal(signal.SIGCHLD, lambda *_: None)
        self.sock.sendall(b"ready\n")
        while True:
            self._report_exits()
            try:
                ready, _, _ = select.select([self.sock.fileno(), wake_r], [], [])
            except InterruptedError:
                continue
            if wake_r in ready:
                os.read(wake_r, 4096)
            if self.sock.fileno() not in ready:
                continue
            data, received, _, _ = socket.recv_fds(self.sock, 1 << 20, 16)
            if not data:
                return None
            self.buffer += data
            self.fds += received
            while b"\n" in self.buffer:
                line, _, self.buffer = self.buffer.partition(b"\n")
                child = self._handle(json.loads(line))
                if child is not None:
                    signal.set_wakeup_fd(-1)
                    signal.signal(signal.SIGCHLD, signal.SIG_DFL)
                    for fd in (wake_r, wake_w):
                        os.close(fd)
                    self.sock.close()
                    return child

    def _handle(self, request: dict[str, Any]) -> dict[str, Any] | None:
        if request.get("op") == "reap":
            pid = int(request["pid"])
            if pid in self.reported:
                self.reported.discard(pid)
                with contextlib.suppress(ChildProcessError):
                    os.waitpid(pid, 0)  # a zombie: at once
            return None
        fds, self.fds = self.fds[:2], self.fds[2:]
        count = threads()
        if count != 1:
            self._close(fds)
            self._answer(f"error the zygote has {count} threads; a fork is not safe")
            return None
        try:
            pid = os.fork()
        except OSError as err:
            self._close(fds)
            self._answer(f"error cannot fork: {err.strerror}")
            return None
        if pid == 0:
            _become_child(request, fds)
            return request
        self._close(fds)
        self.running.add(pid)
        self._answer(f"pid {pid}")
        return None

    def _report_exits(self) -> None:
        """Report every child that has ended, leaving it unreaped (WNOWAIT)."""
        for pid in list(self.running):
            try:
                info = os.waitid(os.P_PID, pid, os.WEXITED | os.WNOHANG | os.WNOWAIT)
            except ChildProcessError:
                self.running.discard(pid)
                continue
            if info is None or info.si_pid == 0:
                continue
            code = info.si_status if info.si_code == os.CLD_EXITED else -info.si_status
            self.running.discard(pid)
            self.reported.add(pid)
            self._answer(f"exit {pid} {code}")

    def _answer(self, text: str) -> None:
        with contextlib.suppress(OSError):  # the launcher is gone: EOF ends the loop next
            self.sock.sendall(text.encode() + b"\n")

    @staticmethod
    def _close(fds: list[int]) -> None:
        for fd in fds:
            os.close(fd)


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
        try:
            os.chdir(request["cwd"])
        except OSError as err:  # gone since the launcher looked: one line, as Popen's error
            os.write(2, f"rosl: cannot start in {request['cwd']} (cwd): {err.strerror}\n".encode())
            os._exit(1)
    _retitle(request["argv"])  # before the environment changes: it finds the title's room there
    zone = os.environ.get("TZ")
    os.environ.clear()
    os.environ.update(request["env"])
    if os.environ.get("TZ") != zone:
        time.tzset()  # the rest of the environment is read when used (exec-only: see zygote)
    if request["hold"]:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    signal.signal(signal.SIGINT, signal.default_int_handler)  # as a fresh interpreter has it


def _retitle(argv: list[str]) -> None:
    """Show the node's own command line (``ps``, ``pgrep -f``), as a fresh start would."""
    try:
        from setproctitle import setproctitle
    except ImportError:  # not installed: the zygote's command line stays
        return
    setproctitle(" ".join([sys.executable, *ENTRY, *argv]))
    set_name(os.path.basename(sys.executable))  # its name stays the interpreter's (top, pgrep)


def main(argv: list[str]) -> int:
    """The zygote: warm up, then serve the launcher until it closes the socket."""
    sock = socket.socket(fileno=int(argv[0]))
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the launcher ends it (by closing, or SIGKILL)
    _warm()
    request = _Server(sock).serve()
    if request is None:
        return 0
    from rosl.pkg import entry

    child = list(request["argv"])
    sys.argv = [entry.__file__, *child]  # as `python -m rosl.pkg.entry ...` has it
    sys.orig_argv = [sys.executable, *ENTRY, *child]  # (and its interpreter's command line)
    return entry.main(child)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
