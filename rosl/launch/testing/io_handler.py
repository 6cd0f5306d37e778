"""``proc_output``: every line the launched processes print, and waits for expected text."""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from rosl.launch.event_handlers import ProcessIO  # one class for handlers' and tests' lines
from rosl.launch.testing.asserts import assertInStream
from rosl.launch.testing.util import NoMatchingProcessException, resolveProcesses

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

__unittest = True  # unittest leaves this module's frames out of failure tracebacks


class IoHandler:
    """The output of every launched process, in order and by process (post-shutdown tests)."""

    def __init__(self) -> None:
        self._sequence_list: list[ProcessIO] = []
        self._process_name_dict: dict[str, list[ProcessIO]] = {}
        self._details: dict[Any, dict[str, Any]] = {}

    def track(self, action: Any, details: dict[str, Any]) -> None:
        """Know a started process, also before (or without) any output."""
        self._details[action] = details
        self._process_name_dict.setdefault(details["name"], [])

    def append(self, process_io: ProcessIO) -> None:
        """Record a line."""
        self._sequence_list.append(process_io)
        self._process_name_dict.setdefault(process_io.process_name, []).append(process_io)

    def __iter__(self) -> Iterator[ProcessIO]:
        return iter(list(self._sequence_list))

    def processes(self) -> list[Any]:
        """The actions of the launched processes."""
        return list(self._details)

    def process_names(self) -> list[str]:
        """The labels of the launched processes (``talker-1``)."""
        return list(self._process_name_dict)

    def process_details(self, action: Any) -> dict[str, Any]:
        """Name, command line and pid of one process."""
        return self._details[action]

    def __getitem__(self, key: Any) -> list[ProcessIO]:
        """The output of one process, by action or by its full label."""
        name = key if isinstance(key, str) else self._details[key]["name"]
        return list(self._process_name_dict[name])


class ActiveIoHandler:
    """``proc_output`` while the launch runs: thread-safe, with ``assertWaitFor``."""

    def __init__(self) -> None:
        self._sync_lock = threading.Condition()
        self._io_handler = IoHandler()

    @property
    def io_event(self) -> threading.Condition:
        """The condition notified on every line and every started process."""
        return self._sync_lock

    def track(self, action: Any, details: dict[str, Any]) -> None:
        """Know a started process."""
        with self._sync_lock:
            self._io_handler.track(action, details)
            self._sync_lock.notify_all()

    def append(self, process_io: ProcessIO) -> None:
        """Record a line and wake the waiters."""
        with self._sync_lock:
            self._io_handler.append(process_io)
            self._sync_lock.notify_all()

    def __iter__(self) -> Iterator[ProcessIO]:
        with self._sync_lock:
            return iter(self._io_handler)

    def processes(self) -> list[Any]:
        """The actions of the launched processes."""
        with self._sync_lock:
            return self._io_handler.processes()

    def process_names(self) -> list[str]:
        """The labels of the launched processes."""
        with self._sync_lock:
            return self._io_handler.process_names()

    def process_details(self, action: Any) -> dict[str, Any]:
        """Name, command line and pid of one process."""
        with self._sync_lock:
            return self._io_handler.process_details(action)

    def __getitem__(self, key: Any) -> list[ProcessIO]:
        with self._sync_lock:
            return self._io_handler[key]

    def assertWaitFor(  # noqa: N802 - launch_testing's name
        self,
        expected_output: Any,
        process: Any = None,
        cmd_args: Any = None,
        *,
        strict_proc_matching: bool = True,
        output_filter: Callable[[str], str] | None = None,
        timeout: float = 10,
        strip_ansi_escape_sequences: bool = True,
        stream: str = "stderr",
    ) -> None:
        """Fail unless ``expected_output`` shows up in ``stream`` within ``timeout`` seconds.

        Args:
            expected_output: a string, a compiled regex, or a list of them (in that order).
            process: an action or (part of) a process label; None: any process.
            cmd_args: arguments that pick among processes of one name.
            strict_proc_matching: a name matching several processes is an error.
            output_filter: applied to the text before matching.
            timeout: seconds.
            strip_ansi_escape_sequences: drop colour codes before matching.
            stream: 'stderr' (where ROS 2 loggers write, the default) or 'stdout'.
        """
        found = self.waitFor(
            expected_output, process, cmd_args, strict_proc_matching=strict_proc_matching,
            output_filter=output_filter, timeout=timeout,
            strip_ansi_escape_sequences=strip_ansi_escape_sequences, stream=stream,
        )  # fmt: skip
        if not found:
            raise AssertionError(
                f"Waiting for output timed out: {expected_output!r} not seen on the {stream} of "
                f"{self._who(process, cmd_args)} within {timeout:g} s{self._tail(process, stream)}"
            )

    def waitFor(  # noqa: N802 - launch_testing's name
        self,
        expected_output: Any,
        process: Any = None,
        cmd_args: Any = None,
        *,
        strict_proc_matching: bool = True,
        output_filter: Callable[[str], str] | None = None,
        timeout: float = 10,
        strip_ansi_escape_sequences: bool = True,
        stream: str = "stderr",
    ) -> bool:
        """Whether ``expected_output`` shows up within ``timeout`` seconds (see assertWaitFor).

        Raises:
            NoMatchingProcessException: at the timeout, no launched process matches ``process``.
        """

        def found() -> bool:
            try:
                assertInStream(
                    self._io_handler, expected_output, process, cmd_args,
                    output_filter=output_filter, strict_proc_matching=strict_proc_matching,
                    strip_ansi_escape_sequences=strip_ansi_escape_sequences, stream=stream,
                )  # fmt: skip
            except (NoMatchingProcessException, AssertionError):
                return False
            return True

        with self._sync_lock:
            success = self._sync_lock.wait_for(found, timeout=timeout)
            if not success:
                try:
                    resolveProcesses(
                        self._io_handler, process=process, cmd_args=cmd_args,
                        strict_proc_matching=False,
                    )  # fmt: skip
                except NoMatchingProcessException as err:
                    raise NoMatchingProcessException(
                        f"After the timeout ({timeout:g} s), found no process matching "
                        f"'{process}': it does not exist or was never launched ({err})"
                    ) from None
        return success

    def _who(self, process: Any, cmd_args: Any) -> str:
        if process is None:
            return "any process"
        with self._sync_lock:
            try:
                actions = resolveProcesses(
                    self._io_handler, process=process, cmd_args=cmd_args, strict_proc_matching=False
                )
            except NoMatchingProcessException:
                return repr(process)
            return ", ".join(self._io_handler.process_details(a)["name"] for a in actions)

    def _tail(self, process: Any, stream: str) -> str:
        fd = 2 if stream == "stderr" else 1
        with self._sync_lock:
            lines = [
                io.text.decode("utf-8", "replace").rstrip("\n")
                for io in self._io_handler
                if io.fd == fd
                and (
                    process is None
                    or (isinstance(process, str) and process in io.process_name)
                    or io.action is process
                )
            ]
        if not lines:
            return f" (nothing was printed on {stream})"
        return "; the last lines:\n" + "\n".join(f"    {line}" for line in lines[-3:])


__all__ = ["ActiveIoHandler", "IoHandler", "ProcessIO"]
