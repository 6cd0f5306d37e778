"""Events aimed at launched processes (launch.events.process) and the matchers that aim them.

``EmitEvent(event=ShutdownProcess(process_matcher=matches_action(talker)))`` stops one process
the way the launch stops all of them at its end (SIGINT, then SIGTERM, then SIGKILL);
``SignalProcess(signal_number=..., process_matcher=...)`` sends one signal. A matcher is a
callable taking a process's action and saying whether the event is meant for it; the
``matches_*`` functions build the usual ones (by action, name, pid or executable).
"""

from __future__ import annotations

import os
import signal
from typing import TYPE_CHECKING, Any

from rosl.launch.errors import LaunchError

if TYPE_CHECKING:
    from collections.abc import Callable


def _details(action: Any) -> dict[str, Any]:
    return dict(getattr(action, "process_details", None) or {})


def matches_action(target_action: Any) -> Callable[[Any], bool]:
    """A matcher for the process(es) started by ``target_action`` (launch.events)."""
    return lambda action: action is target_action


def matches_name(name: str) -> Callable[[Any], bool]:
    """A matcher for the process labelled ``name`` (``talker-1``)."""
    return lambda action: _details(action).get("name") == name


def matches_pid(pid: int) -> Callable[[Any], bool]:
    """A matcher for the process with this pid."""
    return lambda action: _details(action).get("pid") == pid


def matches_executable(executable: str) -> Callable[[Any], bool]:
    """A matcher for processes whose command line starts with ``executable``."""

    def matcher(action: Any) -> bool:
        cmd = _details(action).get("cmd") or [""]
        return str(cmd[0]) == executable or os.path.basename(str(cmd[0])) == executable

    return matcher


class ProcessTargetedEvent:
    """Base of the events aimed at processes: ``process_matcher`` picks them."""

    def __init__(self, *, process_matcher: Callable[[Any], bool]) -> None:
        if not callable(process_matcher):
            raise LaunchError(
                f"{type(self).__name__}(process_matcher=...) needs a callable such as "
                f"launch.events.matches_action(action), not {type(process_matcher).__name__}"
            )
        self.process_matcher = process_matcher


class ShutdownProcess(ProcessTargetedEvent):
    """Stop the matching processes: SIGINT, then SIGTERM and SIGKILL after their timeouts."""


class SignalProcess(ProcessTargetedEvent):
    """Send one signal (a number, ``signal.SIGUSR1`` or a name like ``'SIGUSR1'``)."""

    def __init__(self, *, signal_number: int | str, process_matcher: Callable[[Any], bool]) -> None:
        super().__init__(process_matcher=process_matcher)
        self.signal_number = signal_number

    @property
    def signal(self) -> signal.Signals:
        """The signal as a ``signal.Signals``.

        Raises:
            LaunchError: not a signal this system knows.
        """
        number = self.signal_number
        try:
            if isinstance(number, str):
                return signal.Signals[number if number.startswith("SIG") else f"SIG{number}"]
            return signal.Signals(number)
        except (KeyError, ValueError):
            raise LaunchError(f"SignalProcess: '{number}' is not a signal") from None

    @property
    def signal_name(self) -> str:
        """``SIGUSR1``."""
        return self.signal.name


def emit_to_processes(event: ProcessTargetedEvent, supervisor: Any) -> None:
    """Deliver a process event through the supervisor."""
    if isinstance(event, SignalProcess):
        supervisor.signal_processes(event.process_matcher, event.signal)
    else:
        supervisor.shutdown_processes(event.process_matcher)


class IncludeLaunchDescription:
    """An event that adds a launch description to a running launch (launch.events)."""

    def __init__(self, launch_description: Any) -> None:
        self.launch_description = launch_description
