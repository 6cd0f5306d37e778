"""launch_testing.util: finding launched processes by action or name, and ``KeepAliveProc``.

A process is named as the launcher labels it (``talker-1``); a string matches every process
whose label contains it, ``cmd_args`` narrow that down by the command line's arguments.
"""

from __future__ import annotations

import sys
from typing import Any, Protocol

__unittest = True  # unittest leaves this module's frames out of failure tracebacks

NO_CMD_ARGS = object()  # cmd_args=NO_CMD_ARGS: only a process started without arguments


class NoMatchingProcessException(Exception):  # noqa: N818 - launch_testing's name
    """No launched process matches the given action or name."""


class ProcessRecords(Protocol):
    """What ``proc_info`` and ``proc_output`` have in common: the processes they know."""

    def processes(self) -> list[Any]:
        """The actions of the known processes."""

    def process_details(self, action: Any) -> dict[str, Any]:
        """``{'name': 'talker-1', 'cmd': [...], 'pid': ...}`` of one of them."""


def _describe(info_obj: ProcessRecords, action: Any) -> str:
    details = info_obj.process_details(action)
    return " ".join([details["name"], *details["cmd"][1:]])


def _matches(details: dict[str, Any], name: str, cmd_args: Any) -> bool:
    if name not in details["name"]:
        return False
    if cmd_args is None:
        return True
    if cmd_args is NO_CMD_ARGS:
        return len(details["cmd"]) == 1
    wanted = [cmd_args] if isinstance(cmd_args, str) else list(cmd_args)
    return all(arg in details["cmd"][1:] for arg in wanted)


def resolveProcesses(  # noqa: N802 - launch_testing's name
    info_obj: ProcessRecords,
    *,
    process: Any = None,
    cmd_args: Any = None,
    strict_proc_matching: bool = True,
) -> list[Any]:
    """The actions of the processes ``process`` means (None: all of them).

    Raises:
        NoMatchingProcessException: nothing matches.
        ValueError: a name matches several processes while ``strict_proc_matching``.
    """
    known = info_obj.processes()
    if process is None:
        if not known:
            raise NoMatchingProcessException("No data recorded for any process")
        return known
    if not isinstance(process, str):
        if any(action is process for action in known):
            return [process]
        raise NoMatchingProcessException(f"No data recorded for process {process!r}")
    found = [a for a in known if _matches(info_obj.process_details(a), process, cmd_args)]
    names = ", ".join(sorted(_describe(info_obj, a) for a in known)) or "none"
    if not found:
        raise NoMatchingProcessException(
            f"Did not find any processes matching name '{process}' and args '{cmd_args}'. "
            f"Procs: {names}"
        )
    if strict_proc_matching and len(found) > 1:
        raise ValueError(
            f"Found multiple processes matching name '{process}' and cmd_args '{cmd_args}'. "
            f"Procs: {names}"
        )
    return found


_KEEP_ALIVE = "import signal\ntry:\n    signal.pause()\nexcept KeyboardInterrupt:\n    pass\n"


def KeepAliveProc() -> Any:  # noqa: N802 - launch_testing's name
    """A process that only waits for Ctrl-C: it keeps the launch up while the tests run."""
    from rosl.launch.actions import ExecuteProcess

    return ExecuteProcess(cmd=[sys.executable, "-c", _KEEP_ALIVE], name="keep_alive")


__all__ = ["NO_CMD_ARGS", "KeepAliveProc", "NoMatchingProcessException", "resolveProcesses"]
