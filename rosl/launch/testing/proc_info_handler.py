"""``proc_info``: the start and exit of every launched process, and waits on them."""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.launch.testing.util import NoMatchingProcessException, resolveProcesses

if TYPE_CHECKING:
    from collections.abc import Iterator

__unittest = True  # unittest leaves this module's frames out of failure tracebacks


@dataclass(frozen=True, slots=True)
class ProcessStarted:
    """A launched process started (launch.events.process.ProcessStarted)."""

    action: Any
    process_name: str
    pid: int
    cmd: list[str] = field(default_factory=list)


@dataclass(frozen=True, slots=True)
class ProcessExited:
    """A launched process exited (launch.events.process.ProcessExited)."""

    action: Any
    process_name: str
    pid: int
    cmd: list[str] = field(default_factory=list)
    returncode: int = 0


ProcessEvent = ProcessStarted | ProcessExited


class ProcInfoHandler:
    """The latest event of each launched process (what post-shutdown tests get)."""

    def __init__(self) -> None:
        self._proc_info: dict[Any, ProcessEvent] = {}

    def append(self, process_info: ProcessEvent) -> None:
        """Record a start or an exit."""
        self._proc_info[process_info.action] = process_info

    def __iter__(self) -> Iterator[ProcessEvent]:
        return iter(list(self._proc_info.values()))

    def processes(self) -> list[Any]:
        """The actions of the recorded processes."""
        return list(self._proc_info)

    def process_names(self) -> list[str]:
        """The labels of the recorded processes (``talker-1``)."""
        return [info.process_name for info in self._proc_info.values()]

    def process_details(self, action: Any) -> dict[str, Any]:
        """Name, command line and pid of one process."""
        info = self._proc_info[action]
        return {"name": info.process_name, "cmd": list(info.cmd), "pid": info.pid}

    def __getitem__(self, key: Any) -> ProcessEvent:
        """The latest event of a process, by action or by (part of its) name."""
        if isinstance(key, str):
            for info in self._proc_info.values():
                if key in info.process_name:
                    return info
            raise KeyError(key)
        return self._proc_info[key]


class ActiveProcInfoHandler:
    """``proc_info`` while the launch runs: thread-safe, with waits for start and exit."""

    def __init__(self) -> None:
        self._sync_lock = threading.Condition()
        self._proc_info_handler = ProcInfoHandler()

    @property
    def proc_event(self) -> threading.Condition:
        """The condition notified on every start and exit."""
        return self._sync_lock

    def append(self, process_info: ProcessEvent) -> None:
        """Record a start or an exit and wake the waiters."""
        with self._sync_lock:
            self._proc_info_handler.append(process_info)
            self._sync_lock.notify_all()

    def __iter__(self) -> Iterator[ProcessEvent]:
        with self._sync_lock:
            return iter(list(self._proc_info_handler))

    def processes(self) -> list[Any]:
        """The actions of the recorded processes."""
        with self._sync_lock:
            return self._proc_info_handler.processes()

    def process_names(self) -> list[str]:
        """The labels of the recorded processes."""
        with self._sync_lock:
            return self._proc_info_handler.process_names()

    def process_details(self, action: Any) -> dict[str, Any]:
        """Name, command line and pid of one process."""
        with self._sync_lock:
            return self._proc_info_handler.process_details(action)

    def __getitem__(self, key: Any) -> ProcessEvent:
        with self._sync_lock:
            return self._proc_info_handler[key]

    def _wait(self, process: Any, cmd_args: Any, timeout: float, exited: bool) -> bool:
        def reached() -> bool:
            try:
                action = resolveProcesses(
                    self._proc_info_handler, process=process, cmd_args=cmd_args
                )[0]
            except NoMatchingProcessException:
                return False
            return not exited or isinstance(self._proc_info_handler[action], ProcessExited)

        with self._sync_lock:
            return self._sync_lock.wait_for(reached, timeout=timeout)

    def assertWaitForShutdown(  # noqa: N802 - launch_testing's name
        self, process: Any, cmd_args: Any = None, *, timeout: float = 10
    ) -> None:
        """Fail unless the process has exited within ``timeout`` seconds."""
        if not self._wait(process, cmd_args, timeout, True):
            raise AssertionError(f"Timed out waiting for process '{process}' to finish")

    def assertWaitForStartup(  # noqa: N802 - launch_testing's name
        self, process: Any, cmd_args: Any = None, *, timeout: float = 10
    ) -> None:
        """Fail unless the process has started within ``timeout`` seconds."""
        if not self._wait(process, cmd_args, timeout, False):
            raise AssertionError(f"Timed out waiting for process '{process}' to start")
