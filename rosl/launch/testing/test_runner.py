"""Running one launch test: the launch on this thread, the active tests on another.

As launch_testing does: the launch description starts; once its ReadyToTest action runs, the
active tests run on a second thread while the supervisor watches the processes; when they end,
the launch is shut down (SIGINT, then escalation), and the post-shutdown tests run with every
exit code and line of output. Without ``launch_testing.markers.keep_alive`` the launch also ends
when its last process does; active tests still running then fail the run.
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time
import unittest
from dataclasses import dataclass, field
from typing import IO, TYPE_CHECKING, Any

from rosl.launch.testing.io_handler import ActiveIoHandler, ProcessIO
from rosl.launch.testing.proc_info_handler import (
    ActiveProcInfoHandler,
    ProcessExited,
    ProcessStarted,
)

if TYPE_CHECKING:
    from rosl.launch.context import LaunchContext
    from rosl.launch.records import ProcessEvent
    from rosl.launch.supervisor import Supervisor
    from rosl.launch.testing.loader import TestRun

DIED = "Processes under test stopped before tests completed"
GRACE_SEC = 0.5  # once the active tests are done: a process ending just then ends by itself


@dataclass(slots=True)
class RunResult:
    """The results of one launch test: unittest results, or why the active tests never ended."""

    results: list[unittest.TestResult] = field(default_factory=list)
    problem: str | None = None  # the launch ended before the active tests did
    interrupted: bool = False  # Ctrl-C

    def wasSuccessful(self) -> bool:  # noqa: N802 - unittest's word
        """Whether every test passed and the launch lasted until the active tests ended."""
        return self.problem is None and all(r.wasSuccessful() for r in self.results)

    def failures(self) -> list[tuple[str, str]]:
        """(``Class.test_method``, formatted traceback) of every failed or broken test."""
        return [
            (f"{type(test).__name__}.{getattr(test, '_testMethodName', test)}", text)
            for result in self.results
            for test, text in [*result.errors, *result.failures]
        ]


class TimedTestResult(unittest.TextTestResult):
    """unittest's verbose result, also keeping every test run and its time (for JUnit XML)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.testCases: list[unittest.TestCase] = []
        self.testTimes: dict[unittest.TestCase, float] = {}
        self._started_at = 0.0

    def startTest(self, test: unittest.TestCase) -> None:  # noqa: N802 - unittest's name
        """Note the start."""
        self._started_at = time.monotonic()
        super().startTest(test)

    def stopTest(self, test: unittest.TestCase) -> None:  # noqa: N802 - unittest's name
        """Note the time taken."""
        super().stopTest(test)
        self.testCases.append(test)
        self.testTimes[test] = time.monotonic() - self._started_at


class LaunchServiceHandle:
    """What tests get as ``launch_service``: end the launch early, or emit events into it."""

    def __init__(self, supervisor: Supervisor) -> None:
        self._supervisor = supervisor
        self.context: LaunchContext | None = None  # the launch's, once it runs

    def shutdown(self) -> None:
        """Stop the launched processes (from any thread)."""
        self._supervisor.request_shutdown("shutdown requested by a test")

    def emit_event(self, event: Any) -> None:
        """Act on an event from any thread, on the supervising loop (as launch's queue does).

        ``launch.events.IncludeLaunchDescription`` adds a description to the running launch;
        ``Shutdown``, ``ShutdownProcess`` and ``SignalProcess`` act as EmitEvent does.

        Raises:
            LaunchError: another event, or no launch running.
        """
        from rosl.launch.actions import EmitEvent
        from rosl.launch.errors import LaunchError
        from rosl.launch.events import IncludeLaunchDescription

        if self.context is None:
            raise LaunchError("launch_service.emit_event(): the launch is not running")
        if isinstance(event, IncludeLaunchDescription):
            entities = list(event.launch_description.entities)
        else:
            entities = [EmitEvent(event=event)]
        self._supervisor.request_entities(entities, self.context)


class LaunchTestRunner:
    """Runs one TestRun with rosl's supervisor; prints unittest's verbose results."""

    def __init__(
        self,
        test_run: TestRun,
        arguments: dict[str, str] | None = None,
        *,
        stream: IO[str] | None = None,
    ) -> None:
        from rosl.launch.supervisor import Supervisor

        self.test_run = test_run
        self.arguments = dict(arguments or {})
        self.stream = stream
        self.supervisor = Supervisor()
        self.supervisor.keep_alive = bool(test_run.markers.get("keep_alive", False))
        self.proc_info = ActiveProcInfoHandler()
        self.proc_output = ActiveIoHandler()
        self._ready = threading.Event()
        self._abandoned = False  # the launch failed before the tests could start
        self._completed = threading.Event()
        self._active: unittest.TestResult | None = None
        self._thread = threading.Thread(target=self._run_active, name="launch_test", daemon=True)
        self.launch_service = LaunchServiceHandle(self.supervisor)

    def run(self) -> RunResult:
        """Launch, run the active tests, shut down, run the post-shutdown tests.

        Raises:
            LaunchError: the test description or a launch action is wrong (nothing is left
                running).
            unittest.SkipTest: generate_test_description is skipped.
        """
        description, values = self.test_run.describe(self._ready.set)
        self._bind(values)
        self.supervisor.watchers.append(self._watch)
        self.supervisor.install_signal_handlers()
        try:
            self._launch(description)
        finally:
            self.supervisor.restore_signal_handlers()
        result = RunResult(interrupted=self.supervisor.interrupted)
        if self._ready.is_set() and not self.test_run.pre_shutdown_tests.countTestCases():
            self._thread.join(timeout=10.0)  # no active test: the (empty) run cannot be late
        if not self._completed.is_set():
            result.problem = DIED
            self._print(DIED)
            self._print_failed_processes()
            return result
        assert self._active is not None
        result.results.append(self._active)
        result.results.append(self._unittest(self.test_run.post_shutdown_tests))
        return result

    def _launch(self, description: Any) -> None:
        from rosl.launch.context import LaunchContext
        from rosl.launch.description import check_required_arguments, process

        supervisor = self.supervisor
        supervisor.log("INFO", "launch", f"All log files can be found below {supervisor.log_dir}")
        supervisor.log("INFO", "launch", "Default logging verbosity is set to INFO")
        context = LaunchContext(supervisor, self.arguments)
        context.files.append(self.test_run.path)
        self.launch_service.context = context
        self._thread.start()
        try:
            check_required_arguments(description, context, self.test_run.path)
            process(description.entities, context)
        except BaseException:
            self._abandoned = True
            self._ready.set()
            supervisor.shutdown("the launch description failed")
            supervisor.run()
            raise
        supervisor.run()

    def _bind(self, values: dict[str, Any]) -> None:
        common = {**values, **self.test_run.parameters, "test_args": dict(self.arguments)}
        self.test_run.bind(self.test_run.pre_shutdown_tests, {
            **common, "proc_info": self.proc_info, "proc_output": self.proc_output,
            "launch_service": self.launch_service,
        })  # fmt: skip
        self.test_run.bind(self.test_run.post_shutdown_tests, {
            **common, "proc_info": self.proc_info._proc_info_handler,
            "proc_output": self.proc_output._io_handler,
        })  # fmt: skip

    def _watch(self, event: ProcessEvent) -> None:  # on the supervising thread
        if event.kind in ("stdout", "stderr"):
            text = (event.text + "\n").encode()
            fd = 1 if event.kind == "stdout" else 2
            self.proc_output.append(ProcessIO(event.action, event.name, event.pid, text, fd))
            return
        details = {"name": event.name, "cmd": list(event.cmd), "pid": event.pid}
        if event.kind == "start":
            self.proc_output.track(event.action, details)
            self.proc_info.append(ProcessStarted(event.action, event.name, event.pid, event.cmd))
            with contextlib.suppress(AttributeError):  # as launch's ExecuteProcess has it
                event.action.process_details = details
        elif event.kind == "exit":
            code = event.returncode if event.returncode is not None else -1
            exited = ProcessExited(event.action, event.name, event.pid, event.cmd, code)
            self.proc_info.append(exited)

    def _run_active(self) -> None:  # the test thread
        if not self._ready.wait(self.test_run.timeout):
            self._print("Timed out waiting for processes to start up")
            self.supervisor.request_shutdown("ReadyToTest did not run in time")
            return
        if self._abandoned:
            return
        try:
            self._active = self._unittest(self.test_run.pre_shutdown_tests)
        finally:
            self._completed.set()
            self.supervisor.request_shutdown("the active tests have finished", grace=GRACE_SEC)

    def _unittest(self, suite: unittest.TestSuite) -> unittest.TestResult:
        runner = unittest.TextTestRunner(
            stream=self.stream or sys.stderr, verbosity=2, resultclass=TimedTestResult
        )
        return runner.run(suite)

    def _print(self, text: str) -> None:
        print(text, file=self.stream or sys.stdout, flush=True)

    def _print_failed_processes(self) -> None:
        for info in self.proc_info:
            if not isinstance(info, ProcessExited) or info.returncode == 0:
                continue
            self._print(f"Process '{info.process_name}' exited with {info.returncode}")
            banner = f"##### '{info.process_name}' output #####"
            self._print(banner)
            try:
                lines = self.proc_output[info.action]
            except KeyError:
                lines = []
            for io in lines:
                self._print(io.text.decode("utf-8", "replace").rstrip("\n"))
            self._print("#" * len(banner))
