"""Running the processes of a launch: output, events, respawn, and a clean shutdown.

Every child runs in its own process group (a terminal's Ctrl-C reaches only the launcher,
which forwards it once) with a parent-death signal, so children die with the launcher even
when it is SIGKILLed. On shutdown each child gets SIGINT, then SIGTERM after
``sigterm_timeout``, then SIGKILL after ``sigkill_timeout`` (ROS 2's defaults: 5 s each).
Output lines are prefixed ``[name-N]`` (coloured on a terminal, plain when piped or with
NO_COLOR) and routed by ``output`` as ROS 2 does: 'screen', 'log' (stdout to the launch log,
stderr to both), 'both'.

Watchers (``Supervisor.watchers``, launch_testing's handlers) see every launched process start,
print a line (stdout or stderr, whatever ``output`` says) and exit, on the supervising thread;
``request_shutdown`` may be called from any thread.
"""

from __future__ import annotations

import collections
import contextlib
import datetime
import errno
import heapq
import itertools
import os
import selectors
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, cast

from rosl.launch import zygote
from rosl.launch.parameter_files import ParameterFiles
from rosl.launch.records import ExecutionComplete, ProcessEvent, ProcessSpec, ShutdownEvent
from rosl.pkg import interrupts

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.launch.context import LaunchContext

REAP_EVERY_S = 1.0  # how often a subreaper launcher reaps what it inherited
_COLORS = ["\033[32m", "\033[34m", "\033[35m", "\033[36m", "\033[33m", "\033[92m", "\033[94m"]


def _prepare_child(hold_sigint: bool) -> None:  # runs in the child between fork and exec
    interrupts.prepare_child(hold_sigint)
    zygote.die_with_parent()  # die with the launcher


@dataclass(slots=True)
class Running:
    """A started process and its output buffers."""

    spec: ProcessSpec
    label: str
    action: Any
    context: LaunchContext | None
    popen: subprocess.Popen[bytes]
    partial: dict[int, bytes] = field(default_factory=dict)
    signals: list[tuple[float, int]] = field(default_factory=list)  # (sent at, signal)
    stopping: bool = False


class Supervisor:
    """Starts, watches and stops the processes of one launch."""

    def __init__(
        self,
        *,
        dry_run: bool = False,
        log_dir: Path | None = None,
        stream: IO[str] | None = None,
        color: bool | None = None,
    ) -> None:
        self.dry_run = dry_run
        self.stream = stream or sys.stdout
        self.color = (
            self.stream.isatty() and not os.environ.get("NO_COLOR") if color is None else color
        )
        self.log_dir = log_dir or _default_log_dir()
        self.planned: list[ProcessSpec] = []
        self.failed: list[str] = []
        self.started = 0
        self._counter = itertools.count(1)
        self.parameter_files = ParameterFiles(self.log_dir, dry_run=dry_run)
        self._running: list[Running] = []
        self._handlers: list[tuple[Any, LaunchContext]] = []
        self._timers: list[tuple[float, int, Callable[[], None]]] = []
        self._timer_ids = itertools.count()
        self._respawns: list[tuple[float, int, ProcessSpec, Any, LaunchContext | None, str]] = []
        self._respawned: dict[str, int] = {}  # label -> times respawned
        self._selector = selectors.DefaultSelector()
        self._shutdown_reason: str | None = None
        self._log_file: IO[str] | None = None
        self._interrupts = 0
        self._previous_handlers: dict[int, Any] | None = None
        self._signals: list[int] = []  # received, not yet handled
        self.loading = False  # the launch file loads: a first SIGINT raises KeyboardInterrupt
        self.interrupted_while_loading = False  # a SIGINT came before run(): exit 130
        self._before_run = True
        self._busy = 0  # inside start(): a SIGINT waits for its end to interrupt the loading
        self._interrupt_pending = False
        self._watch: tuple[str, str] | None = None
        self._seen = False
        self.watchers: list[Callable[[ProcessEvent], None]] = []  # see every launched process
        self._started: list[tuple[ProcessEvent | ExecutionComplete, LaunchContext]] = []  # next
        self.keep_alive = False  # run() goes on after the last process, until a shutdown
        self._requests: list[tuple[str, float]] = []  # shutdowns asked for by other threads
        self._entities: list[tuple[list[Any], LaunchContext]] = []  # from other threads too
        self._soon: collections.deque[Callable[[], None]] = collections.deque()  # other threads'
        self._zygote: zygote.Zygote | None = None
        self._zygote_failed = False
        self._subreaper = False  # orphans come to this process: reaped every REAP_EVERY_S
        self._next_reap = 0.0
        self._zygote_partial: dict[Any, bytes] = {}
        self.screen_closed = False  # the stream's reader went away (a closed pipe)

    # --- logging -----------------------------------------------------------------------------

    def _log_handle(self) -> IO[str] | None:
        if self._log_file is None and not self.dry_run:
            try:
                self.log_dir.mkdir(parents=True, exist_ok=True)
                self._log_file = (self.log_dir / "launch.log").open("a", encoding="utf-8")
            except OSError:
                return None
        return self._log_file

    def log(self, level: str, name: str, text: str) -> None:
        """Print ``[LEVEL] [name]: text`` (and keep it in launch.log)."""
        line = f"[{level}] [{name}]: {text}"
        self._write_screen(line)
        self._write_log(line)

    def _write_screen(self, line: str) -> None:
        if self.screen_closed:
            return
        try:
            self.stream.write(line + "\n")
            self.stream.flush()
        except BrokenPipeError:
            # whoever read the output is gone (`rosl launch ... | head`): as a Ctrl-C, the
            # processes are stopped; the rest of the output still goes to launch.log
            self.screen_closed = True
            self.request_shutdown("standard output closed")
        except (OSError, ValueError):
            pass

    def _write_log(self, line: str) -> None:
        handle = self._log_handle()
        if handle is not None:
            handle.write(f"{time.time():.7f} {line}\n")
            handle.flush()

    # --- starting ----------------------------------------------------------------------------

    def start(
        self,
        spec: ProcessSpec,
        action: Any,
        context: LaunchContext | None,
        label: str | None = None,
    ) -> str:
        """Start a process (or, in a dry run, just record it); return its ``name-N`` label."""
        self._busy += 1  # a Ctrl-C now must not leave a started process untracked
        try:
            return self._start(spec, action, context, label)
        finally:
            self._busy -= 1
            if self._interrupt_pending and not self._busy:
                self._interrupt_pending = False
                raise KeyboardInterrupt

    def _start(
        self, spec: ProcessSpec, action: Any, context: LaunchContext | None, label: str | None
    ) -> str:
        self.planned.append(spec)
        label = label or f"{spec.name}-{next(self._counter)}"
        self._handle_signals()  # a Ctrl-C meanwhile: start nothing more
        if self.dry_run or self._shutdown_reason is not None:
            return label
        env = interrupts.child_environment(spec.cmd, {**spec.env, "PYTHONUNBUFFERED": "1"})
        if spec.emulate_tty and self.color:
            env.setdefault("RCUTILS_COLORIZED_OUTPUT", "1")
        hold = interrupts.HELD in env
        try:
            if spec.cwd and not os.path.isdir(spec.cwd):  # as Popen says it, forked or not
                raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), spec.cwd)
            popen = self._forked(spec, env, hold) or subprocess.Popen(
                spec.cmd, env=env, cwd=spec.cwd, stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
                preexec_fn=lambda: _prepare_child(hold),
            )  # fmt: skip
        except OSError as err:
            what = spec.cmd[0]
            if spec.cwd and err.filename == spec.cwd:  # Popen names the folder it failed in
                what = f"{spec.cmd[0]} in {spec.cwd} (cwd)"
            self.log("ERROR", label, f"cannot start {what}: {err.strerror}")
            self.failed.append(label)
            return label
        self.started += 1
        running = Running(spec, label, action, context, popen)
        self._running.append(running)
        for pipe in (popen.stdout, popen.stderr):
            assert pipe is not None
            os.set_blocking(pipe.fileno(), False)
            self._selector.register(pipe, selectors.EVENT_READ, running)
        self.log("INFO", label, f"process started with pid [{popen.pid}]")
        with contextlib.suppress(AttributeError):  # as launch's ExecuteProcess has them
            action.process_details = {"name": label, "cmd": list(spec.cmd), "pid": popen.pid,
                                      "cwd": spec.cwd, "env": spec.env}  # fmt: skip
        started = ProcessEvent("start", action, label, popen.pid, None, spec.cmd)
        self._notify(running, started)
        if context is not None:  # handlers see it from the loop, as launch's event queue has it:
            self._started.append((started, context))  # also those registered after the action
        return label

    def prepare_zygote(self) -> None:
        """Start the pre-imported interpreter rosl nodes are forked from (if not yet)."""
        if (
            self._zygote is None
            and not self._zygote_failed
            and not self.dry_run
            and zygote.wanted()
        ):
            try:
                self._zygote = zygote.Zygote()
            except OSError as err:
                self._zygote_failed = True
                self.log("WARNING", "launch", f"nodes start in fresh interpreters: {err}")
                return
            zygote.become_subreaper()  # should it die, its nodes become ours
            self._subreaper = True  # and so do processes left behind by any process's child
            # its reports wake the loop (data None); its own output is shown prefixed
            self._selector.register(self._zygote.sock, selectors.EVENT_READ, None)
            for pipe, tag in (
                (self._zygote.popen.stdout, "out"),
                (self._zygote.popen.stderr, "err"),
            ):
                assert pipe is not None
                os.set_blocking(pipe.fileno(), False)
                self._selector.register(pipe, selectors.EVENT_READ, tag)

    def _close_zygote(self) -> None:
        if self._zygote is not None:
            for item in (self._zygote.sock, self._zygote.popen.stdout, self._zygote.popen.stderr):
                with contextlib.suppress(KeyError, ValueError, TypeError):
                    assert item is not None
                    self._selector.unregister(item)
            self._zygote.close()
            self._zygote = None

    def _forked(self, spec: ProcessSpec, env: dict[str, str], hold: bool) -> Any:
        """A rosl node forked from the pre-imported zygote, or None to start it afresh."""
        base = None if self._zygote is None else self._zygote.env
        if self._zygote_failed or not zygote.can_fork(spec.cmd, env, base):
            return None
        self.prepare_zygote()
        if self._zygote is None:
            return None
        try:
            return self._zygote.spawn(spec.cmd, env, spec.cwd, hold)
        except OSError as err:  # fresh interpreters from now on; its nodes run on
            self._zygote_failed = True
            self.log("WARNING", "launch", f"nodes start in fresh interpreters: {err}")
            return None

    def wait_for_line(self, label: str, text: str, timeout: float) -> bool:
        """Supervise until process ``label`` prints a line containing ``text`` (bounded)."""
        deadline = time.monotonic() + timeout
        self._watch = (label, text)
        self._seen = False
        while not self._seen and time.monotonic() < deadline and not self.stopping:
            if not any(r.label == label for r in self._running):
                break
            self._step()
        self._watch = None
        return self._seen

    def call_later(self, seconds: float, function: Callable[[], None]) -> None:
        """Run ``function`` after ``seconds`` (TimerAction)."""
        heapq.heappush(self._timers, (time.monotonic() + seconds, next(self._timer_ids), function))

    def add_handler(self, handler: Any, context: LaunchContext) -> None:
        """Register an OnProcessStart/OnProcessExit handler."""
        self._handlers.append((handler, context))

    def call_soon_threadsafe(self, function: Callable[[], None]) -> None:
        """Run ``function`` on the supervising loop (from any thread; within 0.1 s)."""
        self._soon.append(function)

    def emit(self, event: Any) -> None:
        """Give ``event`` (with ``kind`` and ``action``) to the handlers that match it."""
        self._emit(event, None)

    def _notify(self, running: Running, event: ProcessEvent) -> None:
        if running.action is not None:  # not the launcher's own helpers (the recorder)
            for watcher in self.watchers:
                watcher(event)

    def _emit(
        self,
        event: ProcessEvent | ShutdownEvent | ExecutionComplete,
        context: LaunchContext | None,
    ) -> None:
        from rosl.launch.description import process_for_event

        for handler, handler_context in list(self._handlers):
            if handler.matches(event):
                process_for_event(handler, event, handler_context)

    def completed(self, action: Any, context: LaunchContext) -> None:
        """``action`` has done its work: the OnExecutionComplete handlers hear of it from the loop.

        As launch's event queue has it: also those registered after the action.
        """
        self._started.append((ExecutionComplete(action), context))  # from the loop, in order

    def request_entities(self, entities: list[Any], context: LaunchContext) -> None:
        """Process launch entities on the supervising loop (from any thread)."""
        self._entities.append((list(entities), context))

    def shutdown_processes(self, matcher: Callable[[Any], bool]) -> None:
        """Stop the processes whose action ``matcher`` accepts (SIGINT, then escalation)."""
        for running in self._matching(matcher):
            if not running.stopping:
                self._signal(running, signal.SIGINT)

    def signal_processes(self, matcher: Callable[[Any], bool], signum: int) -> None:
        """Send ``signum`` to the processes whose action ``matcher`` accepts."""
        for running in self._matching(matcher):
            self.log("INFO", running.label, f"sending signal '{signal.Signals(signum).name}'")
            if running.popen.poll() is not None:
                continue  # ended: its pid may be another process's by now
            try:
                os.killpg(running.popen.pid, signum)
            except (ProcessLookupError, PermissionError):
                with contextlib.suppress(ProcessLookupError):
                    running.popen.send_signal(signum)

    def _matching(self, matcher: Callable[[Any], bool]) -> list[Running]:
        return [r for r in self._running if r.action is not None and matcher(r.action)]

    # --- the loop ----------------------------------------------------------------------------

    @property
    def stopping(self) -> bool:
        """Whether the launch is shutting down (Ctrl-C, or its work is done)."""
        return self._shutdown_reason is not None

    @property
    def interrupted(self) -> bool:
        """Whether a SIGINT or SIGTERM reached the launcher."""
        return self._interrupts > 0

    def request_shutdown(self, reason: str, grace: float = 0.0) -> None:
        """Ask for ``shutdown(reason, grace)`` from any thread; the supervising loop does it."""
        self._requests.append((reason, grace))

    def shutdown(self, reason: str, grace: float = 0.0) -> None:
        """Stop every process (SIGINT, then escalation) and start nothing more.

        ``grace``: seconds the processes get to end by themselves first (their output is read
        meanwhile); a launch test gives its processes a moment once its tests are done, so one
        that prints and ends at once is not caught by the SIGINT.
        """
        if self._shutdown_reason is not None:
            return
        self._shutdown_reason = reason
        self._timers.clear()
        self._respawns.clear()
        self._emit(ShutdownEvent(reason, self._interrupts > 0), None)  # OnShutdown handlers
        self._drain()
        self._let_end(grace)
        deadline = time.monotonic() + 1.0  # for all of them together
        for running in self._running:
            if running.spec.background:  # helpers (the recorder) stop after the rest
                continue
            if not self._ending_by_itself(running, deadline):
                self._signal(running, signal.SIGINT)

    def _drain(self) -> None:
        """Read what the processes have printed so far (and which have closed their output)."""
        for _ in range(100):  # bounded: a process printing without pause cannot hold us here
            ready = self._selector.select(0)
            if not ready:
                return
            for key, _ in ready:
                self._read(cast("IO[bytes]", key.fileobj), key.data)

    def _let_end(self, grace: float) -> None:
        deadline = time.monotonic() + grace
        while any(r.popen.poll() is None for r in self._running if not r.spec.background):
            left = deadline - time.monotonic()
            if left <= 0:
                return
            for key, _ in self._selector.select(min(left, 0.02)):
                self._read(cast("IO[bytes]", key.fileobj), key.data)

    def _ending_by_itself(self, running: Running, deadline: float) -> bool:
        """A process that has closed its stdout and stderr is exiting: let it (until deadline).

        Else the SIGINT of a shutdown that comes just as it ends turns its clean exit into -2.
        """
        for pipe in (running.popen.stdout, running.popen.stderr):
            if pipe is None:
                continue
            try:
                self._selector.get_key(pipe)  # still open
                return False
            except KeyError:
                continue
        try:
            running.popen.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            return False
        return True

    def _signal(self, running: Running, signum: int) -> None:
        running.stopping = True
        running.signals.append((time.monotonic(), signum))
        if running.popen.poll() is not None:
            return  # ended: its pid may be another process's by now
        try:
            os.killpg(running.popen.pid, signum)
        except (ProcessLookupError, PermissionError):
            with contextlib.suppress(ProcessLookupError):
                running.popen.send_signal(signum)

    def _on_signal(self, signum: int, frame: Any) -> None:
        # only noted here: the handler may run in the middle of a write to the same stream
        # or launch.log, and a reentrant write raises; handled by the loop and by start().
        # While the launch file loads (its own code may take any time), a first SIGINT also
        # ends the loading at once: KeyboardInterrupt, now or as start() ends.
        self._signals.append(signum)
        if signum == signal.SIGINT and self._before_run and not self.interrupted_while_loading:
            self.interrupted_while_loading = True
            if self.loading and self._busy:
                self._interrupt_pending = True
            elif self.loading:
                self.loading = False
                raise KeyboardInterrupt

    def _handle_signals(self) -> None:
        while self._signals:
            self._handle_signal(self._signals.pop(0))
        while self._requests:
            self.shutdown(*self._requests.pop(0))
        while self._entities and self._shutdown_reason is None:
            from rosl.launch.description import process

            entities, context = self._entities.pop(0)
            process(entities, context)

    def _handle_signal(self, signum: int) -> None:
        self._interrupts += 1
        name = "SIGINT" if signum == signal.SIGINT else "SIGTERM"
        if self._interrupts == 1:
            why = (
                "user interrupted with ctrl-c (SIGINT)"
                if signum == signal.SIGINT
                else f"signal {name} received"
            )
            self.log("WARNING", "launch", why)
            self.shutdown(why)
        else:  # again: do not wait for the grace periods
            for running in self._running:
                self._signal(running, signal.SIGKILL if self._interrupts > 2 else signal.SIGTERM)

    def install_signal_handlers(self) -> None:
        """Take SIGINT and SIGTERM from now on, whatever this process inherited.

        A background job of a shell starts with SIGINT ignored; the launcher takes it anyway
        (as ``ros2 launch`` does), so one ``kill -INT`` always ends the launch.
        """
        if (
            self._previous_handlers is None
            and threading.current_thread() is threading.main_thread()
        ):
            self._previous_handlers = {
                s: signal.signal(s, self._on_signal) for s in (signal.SIGINT, signal.SIGTERM)
            }

    def restore_signal_handlers(self) -> None:
        """Give SIGINT and SIGTERM back to what they were before."""
        previous, self._previous_handlers = self._previous_handlers, None
        for sig, handler in (previous or {}).items():
            signal.signal(sig, handler)

    def run(self) -> int:
        """Supervise until every process is gone; return the launch's exit status."""
        installed_here = self._previous_handlers is None
        self.install_signal_handlers()
        self.loading = self._interrupt_pending = self._before_run = False
        try:
            self._handle_signals()  # any received while the launch file loaded
            while (
                self._running
                or self._started
                or (
                    self._shutdown_reason is None
                    and (self._timers or self._respawns or self.keep_alive or self._entities)
                )
            ):
                self._handle_signals()
                foreground = [r for r in self._running if not r.spec.background]
                pending = (self._timers or self._respawns or self.keep_alive or self._started
                           or self._entities)  # fmt: skip
                if self._shutdown_reason is None and not foreground and not pending:
                    self.shutdown("all processes have finished")
                if self._shutdown_reason is not None:
                    # started while the Ctrl-C was being handled: stop it too
                    for running in foreground:
                        if not running.stopping:
                            self._signal(running, signal.SIGINT)
                    if not foreground:
                        for helper in self._running:  # the last one left: stop the helpers now
                            if not helper.stopping:
                                self._signal(helper, signal.SIGINT)
                self._step()
            if self._shutdown_reason is None:  # the last process ended: the launch is done
                self.shutdown("all processes have finished")  # (OnShutdown handlers run)
        finally:
            self.kill_all()
            self._close_zygote()
            if self._subreaper:  # the launch is over: this process (maybe a test's) is not
                zygote.become_subreaper(False)  # a subreaper any longer (first: an orphan
                zygote.reap_orphans()  # ending after the last reap would stay a zombie)
                self._subreaper = False
            if installed_here:
                self.restore_signal_handlers()
            if self._log_file is not None:
                self._log_file.close()
        return 1 if self.failed else 0

    def _step(self) -> None:
        self._handle_signals()
        while self._soon:
            self._soon.popleft()()
        while self._started:  # start events, once what started them has been processed
            event, where = self._started.pop(0)
            self._emit(event, where)
        now = time.monotonic()
        wait = 0.1
        if self._timers:
            wait = min(wait, max(0.0, self._timers[0][0] - now))
        for key, _ in self._selector.select(wait):
            self._read(cast("IO[bytes]", key.fileobj), key.data)  # only pipes are registered
        now = time.monotonic()
        while self._timers and self._timers[0][0] <= now and self._shutdown_reason is None:
            _, _, function = heapq.heappop(self._timers)
            function()
        for entry in [r for r in self._respawns if r[0] <= now]:
            self._respawns.remove(entry)
            _, _, spec, action, context, label = entry
            self.start(spec, action, context, label)
        for running in list(self._running):
            if running.popen.poll() is not None:
                self._finish(running)
            elif running.stopping:
                self._escalate(running, now)
        if self._subreaper and now >= self._next_reap:
            self._next_reap = now + REAP_EVERY_S
            zygote.reap_orphans()

    def _escalate(self, running: Running, now: float) -> None:
        sent_at, last = running.signals[-1]
        timeout = (
            running.spec.sigterm_timeout if last == signal.SIGINT else running.spec.sigkill_timeout
        )
        if last == signal.SIGKILL or now - sent_at < timeout:
            return
        following = signal.SIGTERM if last == signal.SIGINT else signal.SIGKILL
        # ROS 2 prints the time since SIGINT: the SIGKILL step shows both timeouts added up
        # (as a float, '10.0': launch computes it with a PythonExpression)
        shown = (
            f"{timeout:g}"
            if last == signal.SIGINT
            else str(float(running.spec.sigterm_timeout + timeout))
        )
        self.log(
            "ERROR", running.label,
            f"process[{running.label}] failed to terminate '{shown}' seconds after receiving "
            f"'{signal.Signals(last).name}', escalating to '{signal.Signals(following).name}'",
        )  # fmt: skip
        self._signal(running, following)

    def _read(self, pipe: IO[bytes], running: Running | str | None) -> None:
        if running is None:  # the zygote reports exits
            if self._zygote is not None:
                self._zygote.collect()
                if self._zygote.ended:
                    self._selector.unregister(self._zygote.sock)
            return
        if isinstance(running, str):  # the zygote's own output
            self._read_zygote_output(pipe, running)
            return
        stderr = pipe is running.popen.stderr
        for line in self._lines(pipe, running.partial, 2 if stderr else 1):
            self._route(running, line, stderr)

    def _read_zygote_output(self, pipe: IO[bytes], tag: str) -> None:
        for line in self._lines(pipe, self._zygote_partial, tag):
            text = line.decode("utf-8", "replace").rstrip("\r")
            self.log("ERROR" if tag == "err" else "INFO", "launch.zygote", text)

    def _lines(self, pipe: IO[bytes], partial: dict[Any, bytes], key: object) -> list[bytes]:
        """The whole lines now readable from ``pipe`` (at its end, the unfinished one too)."""
        try:
            chunk = os.read(pipe.fileno(), 65536)
        except (BlockingIOError, InterruptedError):
            return []
        except OSError:
            chunk = b""
        data = partial.pop(key, b"") + chunk
        if not chunk:
            self._selector.unregister(pipe)
            return [data] if data else []
        *lines, rest = data.split(b"\n")
        if rest:
            partial[key] = rest
        return lines

    def _route(self, running: Running, raw: bytes, stderr: bool) -> None:
        text = raw.decode("utf-8", "replace").rstrip("\r")
        if self._watch is not None and running.label == self._watch[0] and self._watch[1] in text:
            self._seen = True
        if self.watchers:
            kind = "stderr" if stderr else "stdout"
            pid = running.popen.pid
            self._notify(running, ProcessEvent(kind, running.action, running.label, pid,
                                               None, running.spec.cmd, text))  # fmt: skip
        output = running.spec.output
        to_screen = output in ("screen", "both") or (output == "log" and stderr)
        to_log = output in ("log", "both")
        prefix = f"[{running.label}]"
        if to_screen:
            shown = f"{self._colour(running.spec.name)}{prefix}\033[0m" if self.color else prefix
            self._write_screen(f"{shown} {text}")
        if to_log:
            self._write_log(f"{prefix} {text}")

    def _colour(self, name: str) -> str:
        return _COLORS[sum(name.encode()) % len(_COLORS)]

    def _finish(self, running: Running) -> None:
        for pipe in (running.popen.stdout, running.popen.stderr):
            if pipe is not None:
                while True:
                    try:
                        self._selector.get_key(pipe)
                    except KeyError:
                        break
                    self._read(pipe, running)
        self._running.remove(running)
        code = running.popen.returncode
        pid = running.popen.pid
        if code == 0:
            self.log("INFO", running.label, f"process has finished cleanly [pid {pid}]")
        else:
            cmd = " ".join(running.spec.cmd)
            self.log(
                "ERROR",
                running.label,
                f"process has died [pid {pid}, exit code {code}, cmd '{cmd}'].",
            )
            if not running.stopping:
                self.failed.append(running.label)
        event = ProcessEvent("exit", running.action, running.label, pid, code, running.spec.cmd)
        self._notify(running, event)
        if running.context is not None:
            self._emit(event, running.context)
            on_exit = getattr(running.action, "on_exit", None)
            if on_exit is not None:  # ExecuteProcess(on_exit=...): a handler for itself
                from rosl.launch.actions import OnProcessExit
                from rosl.launch.description import process_for_event

                own = OnProcessExit(target_action=running.action, on_exit=on_exit)
                process_for_event(own, event, running.context)
        retries = running.spec.respawn_max_retries
        if (running.spec.respawn and self._shutdown_reason is None
                and (retries < 0 or self._respawned.get(running.label, 0) < retries)):  # fmt: skip
            self._respawned[running.label] = self._respawned.get(running.label, 0) + 1
            self._respawns.append((time.monotonic() + running.spec.respawn_delay, pid, running.spec,
                                   running.action, running.context, running.label))  # fmt: skip
        elif running.context is not None:  # its work is done (a respawned one goes on)
            self.completed(running.action, running.context)

    def kill_all(self) -> None:
        """Make sure nothing is left running (SIGKILL to every process group)."""
        for running in list(self._running):
            self._signal(running, signal.SIGKILL)
            with contextlib.suppress(subprocess.TimeoutExpired):
                running.popen.wait(timeout=2)
        self._running.clear()


def _default_log_dir() -> Path:
    base = os.environ.get("ROSL_LOG_DIR") or os.path.join(os.path.expanduser("~"), ".rosl", "log")
    stamp = datetime.datetime.now().strftime("%Y-%m-%d-%H-%M-%S-%f")
    return Path(base) / f"{stamp}-{socket.gethostname()}-{os.getpid()}"
