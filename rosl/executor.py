"""spin / spin_once / spin_until_future_complete: one selector loop, and rclpy's Future.

The loop waits on the process's channel sockets (and a wake-up pipe) with a timeout up to the
next due timer, then runs the callbacks of whatever arrived and of the due timers, on the
calling thread. ``MultiThreadedExecutor`` is accepted for compatibility and runs the same loop.
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.context import Context
    from rosl.node.node import Node


class Future:
    """The result of an asynchronous operation (rclpy.task.Future)."""

    def __init__(self) -> None:
        self._done = threading.Event()
        self._result: Any = None
        self._exception: BaseException | None = None
        self._cancelled = False
        self._callbacks: list[Callable[[Future], None]] = []

    def done(self) -> bool:
        """Whether a result, an exception or a cancellation is set."""
        return self._done.is_set()

    def cancelled(self) -> bool:
        """Whether the future was cancelled."""
        return self._cancelled

    def cancel(self) -> None:
        """Cancel the future."""
        if not self.done():
            self._cancelled = True
            self._finish()

    def result(self) -> Any:
        """The result (None if not done); raises the exception if one was set."""
        if self._exception is not None:
            raise self._exception
        return self._result

    def exception(self) -> BaseException | None:
        """The exception set on the future, if any."""
        return self._exception

    def set_result(self, result: Any) -> None:
        """Complete the future with ``result``."""
        self._result = result
        self._finish()

    def set_exception(self, exception: BaseException) -> None:
        """Complete the future with an exception."""
        self._exception = exception
        self._finish()

    def add_done_callback(self, callback: Callable[[Future], None]) -> None:
        """Call ``callback(future)`` when done (at once if already done)."""
        if self.done():
            callback(self)
        else:
            self._callbacks.append(callback)

    def wait(self, timeout: float | None = None) -> bool:
        """Block until done (for use from other threads)."""
        return self._done.wait(timeout)

    def _finish(self) -> None:
        self._done.set()
        for callback in self._callbacks:
            callback(self)
        self._callbacks.clear()


class ExternalShutdownException(Exception):  # noqa: N818 - rclpy's name
    """Raised by spin calls when the context was shut down from outside (rclpy)."""


class Executor:
    """Runs the callbacks of its nodes on the calling thread."""

    def __init__(self, *, context: Context | None = None) -> None:
        from rosl.node.context import default_context

        self.context = context or default_context
        self._nodes: list[Node] = []
        self._stopped = False

    def add_node(self, node: Node) -> bool:
        """Add a node; return False if it was already added."""
        if node in self._nodes:
            return False
        self._nodes.append(node)
        return True

    def remove_node(self, node: Node) -> None:
        """Stop running a node's callbacks."""
        if node in self._nodes:
            self._nodes.remove(node)

    def get_nodes(self) -> list[Node]:
        """The nodes this executor runs."""
        return list(self._nodes)

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        """Stop spinning."""
        del timeout_sec
        self._stopped = True
        participant = self.context.participant
        if participant is not None:
            participant.wake()
        return True

    def _running(self) -> bool:
        return not self._stopped and self.context.ok()

    def spin(self) -> None:
        """Run callbacks until the context shuts down (Ctrl-C) or :meth:`shutdown`."""
        while self._running():
            self.spin_once(timeout_sec=None)

    def spin_once(self, timeout_sec: float | None = None) -> None:
        """Wait up to ``timeout_sec`` (None: until something happens) and run ready callbacks.

        Afterwards, answer a lock-stepped simulator whose messages were handled (see
        :mod:`rosl.node.lockstep`): the answer follows the timers the new ``/clock`` made due.
        """
        ran = self._run_timers()
        participant = self.context.participant
        wait = self._wait_time(timeout_sec)
        if participant is None:
            if wait is None:
                wait = 0.1
            time.sleep(wait)
            self._run_timers()
            return
        answerer = participant.answerer or participant.answer_lockstep()
        participant.poll(wait)
        ran += self._run_timers()
        if answerer.seen:
            answerer.answer(self._next_sim_wakeup(), ran > 0)

    def _next_sim_wakeup(self) -> int:
        """The earliest sim-time timer deadline (ns), -1 when no sim-time timer is armed."""
        soonest = -1
        for timer in self._timers():
            if timer.clock.ros_time_is_active and not timer.is_canceled():
                due = timer.clock.now_ns() + (timer.time_until_next_call() or 0)
                soonest = due if soonest < 0 else min(soonest, due)
        return soonest

    def spin_until_future_complete(self, future: Future, timeout_sec: float | None = None) -> None:
        """Spin until ``future`` is done, the timeout passes, or the context shuts down."""
        deadline = (
            None if timeout_sec is None or timeout_sec < 0 else time.monotonic() + timeout_sec
        )
        while self._running() and not future.done():
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                return
            self.spin_once(timeout_sec=0.05 if remaining is None else min(remaining, 0.05))

    def spin_once_until_future_complete(
        self, future: Future, timeout_sec: float | None = None
    ) -> None:
        """One iteration, returning early if ``future`` completes."""
        if not future.done():
            self.spin_once(timeout_sec)

    def _timers(self) -> list[Any]:
        return [t for node in self._nodes for t in node.timers if not t.destroyed]

    def _wait_time(self, timeout_sec: float | None) -> float | None:
        wait = None if timeout_sec is None or timeout_sec < 0 else timeout_sec
        for timer in self._timers():
            if timer.clock.ros_time_is_active:
                continue  # sim-time timers are woken by /clock arriving
            until = timer.time_until_next_call()
            if until is not None:
                seconds = max(0.0, until / 1e9)
                wait = seconds if wait is None else min(wait, seconds)
        if not self._running():
            return 0.0
        return wait

    def _run_timers(self) -> int:
        ran = 0
        for node in list(self._nodes):
            for timer in list(node.timers):
                if timer.is_ready() and not timer.destroyed:
                    ran += 1
                    node.run_callback(timer.call, "timer")
        return ran


class SingleThreadedExecutor(Executor):
    """rclpy's default executor."""


class MultiThreadedExecutor(Executor):
    """Accepted for compatibility; callbacks run on the spinning thread, one at a time."""

    def __init__(self, num_threads: int | None = None, *, context: Context | None = None) -> None:
        del num_threads
        super().__init__(context=context)
