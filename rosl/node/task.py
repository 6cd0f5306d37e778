"""Future and Task: rclpy's results of asynchronous work, and the coroutines executors run.

A :class:`Task` runs a function or a coroutine. A coroutine that awaits a :class:`Future`
which is not done is suspended; the future's completion hands the task back to its executor
(``_schedule``), which resumes it on the next iteration. rclpy instead re-runs every pending
task on each wake-up; resuming on completion costs nothing while a task waits.
"""

from __future__ import annotations

import inspect
import sys
import threading
from typing import TYPE_CHECKING, Any, Generic, Protocol, TypeVar

if TYPE_CHECKING:
    from collections.abc import Callable, Coroutine, Generator, Iterable


T = TypeVar("T")

_driving = threading.local()  # .task: the rosl Task whose coroutine this thread is running


def current_task() -> Task[Any] | None:
    """The task whose coroutine this thread is running now (None outside of one)."""
    task: Task[Any] | None = getattr(_driving, "task", None)
    return task


class Scheduler(Protocol):
    """What a task needs of its executor: to be run again (an executor's ``_schedule``)."""

    def _schedule(self, task: Task[Any]) -> None: ...


class Future(Generic[T]):
    """The result of an asynchronous operation (rclpy.task.Future)."""

    def __init__(self, *, executor: Any = None) -> None:
        self._done = False
        self._event: threading.Event | None = None  # made by the first wait()
        self._result: T | None = None
        self._exception: BaseException | None = None
        self._cancelled = False
        self._callbacks: list[Callable[[Future[T]], None]] = []
        self._lock = threading.Lock()
        self._executor = executor

    def __await__(self) -> Generator[Future[T] | None, None, T | None]:
        while not self._done:
            # a rosl Task resumes when this future is done; any other driver (an asyncio
            # task, as in rclpy's asyncio examples) gets a bare yield and polls, as with rclpy
            yield self if getattr(_driving, "task", None) is not None else None
        return self.result()

    def done(self) -> bool:
        """Whether a result, an exception or a cancellation is set."""
        return self._done

    def cancelled(self) -> bool:
        """Whether the future was cancelled."""
        return self._cancelled

    def cancel(self) -> None:
        """Cancel the future (no effect once done).

        Done callbacks run; ``done()`` stays False, as in rclpy.
        """
        with self._lock:
            if self._done or self._cancelled:
                return
            self._cancelled = True
        self._finish(done=False)

    def result(self) -> T | None:
        """The result (None if not done); raises the exception if one was set."""
        if self._exception is not None:
            raise self._exception
        return self._result

    def exception(self) -> BaseException | None:
        """The exception set on the future, if any."""
        return self._exception

    def set_result(self, result: T) -> None:
        """Complete the future with ``result``."""
        with self._lock:
            self._result = result
            self._cancelled = False
        self._finish()

    def set_exception(self, exception: BaseException) -> None:
        """Complete the future with an exception."""
        with self._lock:
            self._exception = exception
            self._cancelled = False
        self._finish()

    def add_done_callback(self, callback: Callable[[Future[T]], None]) -> None:
        """Call ``callback(future)`` when done (at once if already done)."""
        with self._lock:
            if not (self._done or self._cancelled):
                self._callbacks.append(callback)
                return
        callback(self)

    def remove_done_callback(self, callback: Callable[[Future[T]], None]) -> bool:
        """Forget a done callback; return whether it was registered."""
        with self._lock:
            if callback in self._callbacks:
                self._callbacks.remove(callback)
                return True
        return False

    def wait(self, timeout: float | None = None) -> bool:
        """Block until done (for threads that do not spin); return whether it is done."""
        with self._lock:
            if self._done or self._cancelled:
                return True
            if self._event is None:
                self._event = threading.Event()
            event = self._event
        return event.wait(timeout)

    def _finish(self, done: bool = True) -> None:
        with self._lock:
            self._done = done
            callbacks, self._callbacks = self._callbacks, []
            event = self._event
        if event is not None:
            event.set()
        for callback in callbacks:
            try:
                callback(self)
            except Exception as err:  # one failing callback must not stop the others
                sys.stderr.write(f"[ERROR] [rosl]: exception in a future's done callback: {err}\n")


class Task(Future[T]):
    """Runs a function or a coroutine to completion (rclpy.task.Task).

    Calling the task runs it, or resumes its coroutine, until it completes or awaits a
    future that is not done yet.
    """

    _internal = False  # (never rosl's housekeeping: see Executor.spin_once)

    def __init__(
        self,
        handler: Callable[..., Any],
        args: Iterable[Any] | None = None,
        kwargs: dict[str, Any] | None = None,
        executor: Scheduler | None = None,
    ) -> None:
        super().__init__(executor=executor)
        self._handler: Callable[..., Any] | None = handler
        self._args = tuple(args or ())
        self._kwargs = kwargs or {}
        self._coroutine: Coroutine[Any, Any, Any] | None = None
        self._executing = False
        self._task_lock = threading.Lock()
        self.entity: Any = None  # what an executor's handler task serves, and its node
        self.node: Any = None
        self.holds: Any = None  # the callback group its coroutine callback keeps taken

    def executing(self) -> bool:
        """Whether the task is running right now."""
        return self._executing

    def __call__(self) -> None:
        """Run the task, or resume it, until it completes or waits for a future."""
        if self._done or self._cancelled:
            return
        # a step on another thread ends soon (at its next await); then this one runs
        with self._task_lock:
            if self._done or self._cancelled:
                return
            self._executing = True
            try:
                self._step()
            finally:
                self._executing = False

    def _step(self) -> None:
        if self._coroutine is None:
            handler, self._handler = self._handler, None
            if handler is None:
                return
            try:
                result = handler(*self._args, **self._kwargs)
            except Exception as err:
                self.set_exception(err)
                return
            if not inspect.iscoroutine(result):
                self.set_result(result)
                return
            self._coroutine = result
        outer = getattr(_driving, "task", None)
        _driving.task = self
        try:
            awaited = self._coroutine.send(None)
        except StopIteration as end:
            self._coroutine = None
            self.set_result(end.value)
            return
        except Exception as err:
            self._coroutine = None
            self.set_exception(err)
            return
        finally:
            _driving.task = outer
        if isinstance(awaited, Future) and not awaited.done():
            awaited.add_done_callback(self._resume)
        else:
            self._resume(None)  # awaited something else (a bare yield): run again soon

    def _resume(self, _: object) -> None:
        executor = self._executor
        if executor is not None and not self._done:
            executor._schedule(self)
