"""What the supervisor is given and what it tells: the process to start, and its events.

``ProcessSpec`` is a process resolved from a launch action; ``ProcessEvent`` (a start, a line,
an exit), ``ExecutionComplete`` and ``ShutdownEvent`` are what event handlers and watchers see.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass(slots=True)
class ProcessSpec:
    """What to start, resolved from a launch action."""

    name: str
    cmd: list[str]
    env: dict[str, str]
    cwd: str | None = None
    output: str = "log"
    respawn: bool = False
    respawn_delay: float = 0.0
    respawn_max_retries: int = -1  # -1: respawn without limit
    emulate_tty: bool = False
    sigterm_timeout: float = 5.0
    sigkill_timeout: float = 5.0
    details: dict[str, Any] = field(default_factory=dict)
    background: bool = False  # e.g. the recorder: stopped after every other process ended


@dataclass(slots=True)
class ProcessEvent:
    """A process started, printed a line or exited (what event handlers and watchers see)."""

    kind: str  # "start" | "exit"; watchers also see "stdout" | "stderr"
    action: Any
    name: str
    pid: int
    returncode: int | None = None
    cmd: list[str] = field(default_factory=list)
    text: str = ""  # the line printed ("stdout"/"stderr" events), without its newline

    @property
    def process_name(self) -> str:
        """The process's label (``talker-1``), as launch's process events name it."""
        return self.name


@dataclass(slots=True)
class ExecutionComplete:
    """An action has done its work (what OnExecutionComplete handlers see).

    A process's action completes when the process has exited for good; a timer's when its
    actions have run; any other action as soon as it has run.
    """

    action: Any
    kind: str = "complete"


@dataclass(slots=True)
class ShutdownEvent:
    """The launch begins to shut down (what OnShutdown handlers see: launch's Shutdown event)."""

    reason: str
    due_to_sigint: bool = False
    kind: str = "shutdown"
    action: Any = None
