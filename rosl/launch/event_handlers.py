"""Event handlers (launch.event_handlers): OnProcessStart/Exit/IO, OnExecutionComplete.

A handler names the process it watches (``target_action``: the action, a predicate taking
the action, or None for every process) and what to run: an action, a list of them, or a
callable returning either. Start and exit reach it through the supervisor's handlers, with
``(event, context)``; printed lines through the supervisor's watchers, with the event only
(``launch.events.process.ProcessIO``: ``text`` as bytes, ``fd``, ``from_stdout``...).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.launch.description import Action, process_for_event
from rosl.launch.errors import LaunchError

if TYPE_CHECKING:
    from rosl.launch.context import LaunchContext
    from rosl.launch.records import ProcessEvent


@dataclass(frozen=True, slots=True)
class ProcessIO:
    """A line a process printed, as OnProcessIO's callables get it (launch's ProcessIO)."""

    action: Any
    name: str
    pid: int
    text: bytes  # the line with its newline
    fd: int  # 1 stdout, 2 stderr
    cmd: list[str] = field(default_factory=list)

    @property
    def process_name(self) -> str:
        """The process's label (``talker-1``), as launch's ProcessIO names it."""
        return self.name

    @property
    def from_stdout(self) -> bool:
        """Printed on stdout."""
        return self.fd == 1

    @property
    def from_stderr(self) -> bool:
        """Printed on stderr."""
        return self.fd == 2

    @property
    def from_stdin(self) -> bool:
        """Never: rosl gives launched processes no stdin."""
        return False


class EventHandler:
    """Base of the handlers: which process events they take, and what they run.

    ``handle_once`` reacts to the first matching event only.
    """

    kinds: tuple[str, ...] = ()

    def __init__(
        self, *, target_action: Any = None, handler: Any = None, handle_once: bool = False
    ) -> None:
        self.target_action = target_action
        self.handler = handler
        self.handle_once = handle_once
        self.handled = False

    def matches(self, event: ProcessEvent) -> bool:
        """Whether this handler reacts to ``event``."""
        if event.kind not in self.kinds or (self.handle_once and self.handled):
            return False
        target = self.target_action
        if target is None:
            return True
        if callable(target) and not hasattr(target, "visit"):
            return bool(target(event.action))
        return target is event.action

    def entities(self, event: ProcessEvent, context: LaunchContext) -> list[Any]:
        """The actions to run for ``event``."""
        self.handled = True
        reaction = self.handler
        if callable(reaction) and not hasattr(reaction, "visit"):
            reaction = reaction(event, context)
        return _as_list(reaction)


def _as_list(reaction: Any) -> list[Any]:
    if reaction is None:
        return []
    return list(reaction) if isinstance(reaction, (list, tuple)) else [reaction]


class OnProcessStart(EventHandler):
    """React when a process starts."""

    kinds = ("start",)

    def __init__(
        self, *, target_action: Any = None, on_start: Any = None, handle_once: bool = False
    ) -> None:
        super().__init__(target_action=target_action, handler=on_start, handle_once=handle_once)


class OnProcessExit(EventHandler):
    """React when a process exits (the event has ``returncode``)."""

    kinds = ("exit",)

    def __init__(
        self, *, target_action: Any = None, on_exit: Any = None, handle_once: bool = False
    ) -> None:
        super().__init__(target_action=target_action, handler=on_exit, handle_once=handle_once)


class OnShutdown(EventHandler):
    """React when the launch begins to shut down: ``on_shutdown(event, context)`` or actions.

    The event has ``reason`` and ``due_to_sigint``. Actions run then can log, not start
    processes: the launch starts nothing more once it shuts down.
    """

    kinds = ("shutdown",)

    def __init__(self, *, on_shutdown: Any = None, handle_once: bool = True) -> None:
        super().__init__(handler=on_shutdown, handle_once=handle_once)


class OnExecutionComplete(EventHandler):
    """React when an action has done its work: ``on_completion(event, context)`` or actions.

    A process's action is done when it exited for good, a timer's when it fired, any other
    action's when it ran; the event has ``action``.
    """

    kinds = ("complete",)

    def __init__(
        self, *, target_action: Any = None, on_completion: Any = None, handle_once: bool = False
    ) -> None:
        super().__init__(
            target_action=target_action, handler=on_completion, handle_once=handle_once
        )


class OnProcessIO(EventHandler):
    """React to each line a process prints: ``on_stdout(event)`` / ``on_stderr(event)``."""

    kinds = ("stdout", "stderr")

    def __init__(
        self,
        *,
        target_action: Any = None,
        on_stdin: Any = None,
        on_stdout: Any = None,
        on_stderr: Any = None,
        handle_once: bool = False,
    ) -> None:
        super().__init__(target_action=target_action, handle_once=handle_once)
        del on_stdin  # launched processes get no stdin
        self.on_stdout = on_stdout
        self.on_stderr = on_stderr

    def entities(self, event: ProcessEvent, context: LaunchContext) -> list[Any]:
        """What the callable for the event's stream returns for it."""
        self.handled = True
        reaction = self.on_stdout if event.kind == "stdout" else self.on_stderr
        if reaction is None:
            return []
        text = (event.text + "\n").encode()
        fd = 1 if event.kind == "stdout" else 2
        return _as_list(
            reaction(ProcessIO(event.action, event.name, event.pid, text, fd, event.cmd))
        )


class RegisterEventHandler(Action):
    """Register an OnProcessStart, OnProcessExit or OnProcessIO handler."""

    def __init__(self, event_handler: EventHandler, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        if not isinstance(event_handler, EventHandler):
            raise LaunchError(
                f"RegisterEventHandler({type(event_handler).__name__}(...)) is not supported by "
                "rosl: its event handlers are OnProcessStart, OnProcessExit, OnProcessIO, "
                "OnExecutionComplete and OnShutdown"
            )
        self.event_handler = event_handler

    def execute(self, context: LaunchContext) -> None:
        """Give the handler to the supervisor (lines reach it as a watcher)."""
        supervisor = context.supervisor
        if supervisor is None:
            return
        handler = self.event_handler
        if not isinstance(handler, OnProcessIO):
            supervisor.add_handler(handler, context)
            return

        def watch(event: ProcessEvent) -> None:
            if handler.matches(event):
                process_for_event(handler, event, context)

        supervisor.watchers.append(watch)
