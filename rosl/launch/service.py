"""launch.LaunchService: run launch descriptions from a Python program, as launch's API does.

::

    service = LaunchService(argv=["rate:=2.0"])
    service.include_launch_description(generate_launch_description())
    code = service.run()  # until every process has ended (or Ctrl-C, or shutdown())

The processes run on rosl's supervisor exactly as under ``rosl launch``; ``shutdown()`` and
``emit_event()`` may be called from any thread while ``run()`` runs.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.launch.context import LaunchContext
from rosl.launch.supervisor import Supervisor

if TYPE_CHECKING:
    from rosl.launch.description import LaunchDescription


class LaunchService:
    """Runs launch descriptions (launch.LaunchService)."""

    def __init__(
        self, *, argv: list[str] | None = None, noninteractive: bool = False, debug: bool = False
    ) -> None:
        from rosl.launch.loader import parse_arguments

        del noninteractive, debug
        arguments = parse_arguments([a for a in argv or [] if ":=" in a])
        self._supervisor = Supervisor()
        self.context = LaunchContext(self._supervisor, arguments)
        self._descriptions: list[LaunchDescription] = []
        self._running = False

    def include_launch_description(self, launch_description: LaunchDescription) -> None:
        """Add a description: processed when run() starts (or at once while it runs)."""
        if self._running:
            self._supervisor.request_entities(list(launch_description.entities), self.context)
        else:
            self._descriptions.append(launch_description)

    def run(self, *, shutdown_when_idle: bool = True) -> int:
        """Process the descriptions and supervise until everything has ended; the exit status.

        Raises:
            LaunchError: a description is wrong (what started is stopped first).
        """
        from rosl.launch.description import process

        supervisor = self._supervisor
        supervisor.keep_alive = not shutdown_when_idle
        supervisor.install_signal_handlers()
        self._running = True
        try:
            supervisor.log(
                "INFO", "launch", f"All log files can be found below {supervisor.log_dir}"
            )
            supervisor.log("INFO", "launch", "Default logging verbosity is set to INFO")
            try:
                for description in self._descriptions:
                    process(description.entities, self.context)
            except BaseException:
                supervisor.shutdown("the launch description failed")
                supervisor.run()
                raise
            return supervisor.run()
        finally:
            self._running = False
            supervisor.restore_signal_handlers()

    def shutdown(self, force_sync: bool = False) -> None:
        """End the launch (from any thread): every process is stopped."""
        del force_sync
        self._supervisor.request_shutdown("LaunchService.shutdown() called")

    def emit_event(self, event: Any) -> None:
        """Act on an event: Shutdown, ShutdownProcess, SignalProcess, IncludeLaunchDescription."""
        from rosl.launch.actions import EmitEvent, Shutdown
        from rosl.launch.events import IncludeLaunchDescription

        if isinstance(event, Shutdown):
            self._supervisor.request_shutdown(event.reason)
        elif isinstance(event, IncludeLaunchDescription):
            self.include_launch_description(event.launch_description)
        else:
            self._supervisor.request_entities([EmitEvent(event=event)], self.context)


__all__ = ["LaunchService"]
