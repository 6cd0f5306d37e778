"""launch_testing.tools' ``ProcessProxy`` and ``launch_process``: a process an active test runs.

::

    with launch_testing.tools.launch_process(
        launch_service, ExecuteProcess(cmd=["ros2", "topic", "list"]), proc_info, proc_output
    ) as command:
        assert command.wait_for_shutdown(timeout=10)
    assert command.exit_code == launch_testing.asserts.EXIT_OK

The process joins the running launch (on the supervising thread) and is stopped, if still
running, when the ``with`` block ends.
"""

from __future__ import annotations

import contextlib
from typing import TYPE_CHECKING, Any

from rosl.launch.testing.io_handler import ActiveIoHandler
from rosl.launch.testing.proc_info_handler import (
    ActiveProcInfoHandler,
    ProcessExited,
    ProcessStarted,
)

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator


class BoolWithText:
    """A truth value that shows the output it was decided on (in a failed ``assert``)."""

    def __init__(self, result: bool, output: str | None) -> None:
        self._result = result
        self._output = output

    def __bool__(self) -> bool:
        return self._result

    def __repr__(self) -> str:
        return f"<BoolWithText({self._result}): {self._output!r}>"


class ProcessProxy:
    """Waits on one launched process and reads its output (launch_testing.tools)."""

    def __init__(
        self,
        process_action: Any,
        proc_info: ActiveProcInfoHandler,
        proc_output: ActiveIoHandler,
        *,
        output_filter: Callable[[str], str] | None = None,
    ) -> None:
        from rosl.launch.actions import ExecuteProcess

        for value, kind, name in ((process_action, ExecuteProcess, "process_action"),
                                  (proc_info, ActiveProcInfoHandler, "proc_info"),
                                  (proc_output, ActiveIoHandler, "proc_output")):  # fmt: skip
            if not isinstance(value, kind):
                raise TypeError(f"Expected '{name}' to be {kind.__name__}, not {value!r}")
        if output_filter is not None and not callable(output_filter):
            raise TypeError(f"Expected 'output_filter' to be callable but got {output_filter!r}")
        self._process_action = process_action
        self._proc_info = proc_info
        self._proc_output = proc_output
        self._output_filter = output_filter

    @property
    def target_process_action(self) -> Any:
        """The ExecuteProcess this proxy watches."""
        return self._process_action

    def _text(self, which: str) -> str:
        try:
            lines = self._proc_output[self._process_action]
        except KeyError:
            return ""
        text = "".join(
            io.text.decode("utf-8", "replace")
            for io in lines
            if which == "output" or (io.from_stdout if which == "stdout" else io.from_stderr)
        )
        return self._output_filter(text) if self._output_filter is not None else text

    @property
    def stdout(self) -> str:
        """What the process printed on stdout (filtered)."""
        return self._text("stdout")

    @property
    def stderr(self) -> str:
        """What the process printed on stderr (filtered)."""
        return self._text("stderr")

    @property
    def output(self) -> str:
        """Everything the process printed, in order (filtered)."""
        return self._text("output")

    def _latest(self) -> Any:
        try:
            return self._proc_info[self._process_action]
        except KeyError:
            return None

    @property
    def running(self) -> bool:
        """Whether the process has started and not exited."""
        return isinstance(self._latest(), ProcessStarted)

    @property
    def terminated(self) -> bool:
        """Whether the process has exited."""
        return isinstance(self._latest(), ProcessExited)

    @property
    def exit_code(self) -> int:
        """The exit code (once terminated)."""
        latest = self._latest()
        if not isinstance(latest, ProcessExited):
            raise AttributeError("the process has not exited (yet): it has no exit code")
        return latest.returncode

    def wait_for_shutdown(self, timeout: float | None = None) -> bool:
        """Wait (at most ``timeout`` seconds) until the process has exited; whether it has."""
        with self._proc_info.proc_event:
            return self._proc_info.proc_event.wait_for(lambda: self.terminated, timeout=timeout)

    def wait_for_output(
        self, condition: Callable[[str], Any] | None = None, timeout: float | None = None
    ) -> BoolWithText:
        """Wait until the output satisfies ``condition`` (any output by default)."""
        check = condition if condition is not None else (lambda output: True)
        if not callable(check):
            raise TypeError(f"Expected 'condition' to be callable but got {condition!r}")
        seen: list[str] = [""]

        def satisfied() -> bool:
            seen[0] = self.output
            return (self.running or self.terminated) and bool(seen[0]) and bool(check(seen[0]))

        with self._proc_output.io_event:
            result = self._proc_output.io_event.wait_for(satisfied, timeout=timeout)
        return BoolWithText(bool(result), seen[0])


@contextlib.contextmanager
def launch_process(
    launch_service: Any,
    process_action: Any,
    proc_info: ActiveProcInfoHandler,
    proc_output: ActiveIoHandler,
    **kwargs: Any,
) -> Iterator[ProcessProxy]:
    """Start ``process_action`` in the running launch; yield its proxy; stop it at the end."""
    from rosl.launch.description import LaunchDescription
    from rosl.launch.events import IncludeLaunchDescription, ShutdownProcess, matches_action

    proxy = ProcessProxy(process_action, proc_info, proc_output, **kwargs)
    launch_service.emit_event(
        IncludeLaunchDescription(launch_description=LaunchDescription([process_action]))
    )
    try:
        yield proxy
    finally:
        if not proxy.terminated:
            launch_service.emit_event(
                ShutdownProcess(process_matcher=matches_action(process_action))
            )
