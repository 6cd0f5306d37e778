"""Executors: run the callbacks of the nodes added to them, as rclpy's do.

Deliveries wait in their entity's queue (a subscription's, a service's, a client's; see
:meth:`rosl.node.participant.Participant.dispatch`). ``wait_for_ready_callbacks`` looks at
the entities of this executor's nodes only — queued deliveries, due timers, triggered guard
conditions, ready waitables, tasks to resume — and yields a handler for each one its callback
group lets run; when nothing is ready it waits on the participant (which polls the transport)
until something is, or the next timer is due. ``SingleThreadedExecutor`` runs each handler on
the spinning thread, ``MultiThreadedExecutor`` in a pool of threads, and a custom executor
decides (rclpy's API: subclass :class:`Executor` and call ``wait_for_ready_callbacks``).

Two choices differ from rclpy, both to remove its classic deadlocks: a client's response
completes its future whatever the client's callback group is doing (so a callback in a
mutually exclusive group may ``await client.call_async(...)``), and ``Client.call`` inside a
callback reads its response itself. A coroutine callback suspended on a future resumes when
the future completes, not by polling.
"""

from __future__ import annotations

import inspect
import os
import threading
import time
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from typing import TYPE_CHECKING, Any

from rosl.node.task import Future, Task

if TYPE_CHECKING:
    from collections.abc import Callable, Coroutine, Generator, Iterable
    from types import TracebackType

    from rosl.node.context import Context
    from rosl.node.node import Node
    from rosl.node.participant import Participant


class TimeoutException(Exception):  # noqa: N818 - rclpy's name
    """``wait_for_ready_callbacks``: nothing became ready within the timeout."""


class ShutdownException(Exception):  # noqa: N818 - rclpy's name
    """``wait_for_ready_callbacks``: the executor was shut down."""


class ExternalShutdownException(Exception):  # noqa: N818 - rclpy's name
    """``wait_for_ready_callbacks``: the context was shut down (Ctrl-C, ``rclpy.shutdown``)."""


class ConditionReachedException(Exception):  # noqa: N818 - rclpy's name
    """``wait_for_ready_callbacks``: the condition given to it became true."""


_STOPS = (TimeoutException, ShutdownException, ExternalShutdownException, ConditionReachedException)


class Ready(tuple[Task[Any], Any, Any]):
    """(handler, entity, node), as ``wait_for_ready_callbacks`` returns it.

    ``next()`` of it is itself, for custom executors written against older rclpy, where
    ``wait_for_ready_callbacks`` returned a generator.
    """

    __slots__ = ()

    def __next__(self) -> Ready:
        return self


class Executor:
    """Runs the callbacks of its nodes (rclpy.executors.Executor); subclasses decide threads.

    The base class runs handlers on the spinning thread, as ``SingleThreadedExecutor``.
    """

    def __init__(self, *, context: Context | None = None) -> None:
        from rosl.node.context import default_context

        self._context = context or default_context
        self._nodes: list[Node] = []
        self._nodes_lock = threading.RLock()
        self._ready_tasks: deque[Task[Any]] = deque()
        self._tasks_lock = threading.Lock()
        self._is_shutdown = False
        self._cb_iter: Generator[Ready, None, None] | None = None
        self._last_args: tuple[Any, ...] | None = None
        self._last_kwargs: dict[str, Any] | None = None
        self._timers_ran = 0  # timer callbacks since the last lock-step answer
        self.answers_lockstep = True  # rosl: answer lock-stepped simulators when idle
        self._work = 0  # handlers running (shutdown waits for them)
        self._work_done = threading.Condition()

    @property
    def context(self) -> Context:
        """The context whose nodes this executor runs."""
        return self._context

    # --- nodes and tasks ---------------------------------------------------------------------

    def add_node(self, node: Node) -> bool:
        """Run ``node``'s callbacks here (a node has one executor); False if it already was."""
        with self._nodes_lock:
            if node in self._nodes:
                return False
            self._nodes.append(node)
        node.executor = self
        self.wake()
        return True

    def remove_node(self, node: Node) -> None:
        """Stop running ``node``'s callbacks."""
        with self._nodes_lock:
            if node not in self._nodes:
                return
            self._nodes.remove(node)
        if node.executor is self:
            node.executor = None
        self.wake()

    def get_nodes(self) -> list[Node]:
        """The nodes this executor runs."""
        with self._nodes_lock:
            return list(self._nodes)

    def create_task(self, callback: Callable[..., Any], *args: Any, **kwargs: Any) -> Task[Any]:
        """Run ``callback(*args, **kwargs)`` (a function or a coroutine function) while spinning."""
        task: Task[Any] = Task(callback, args, kwargs, executor=self)
        self._schedule(task)
        return task

    def create_future(self) -> Future[Any]:
        """A future tied to this executor."""
        return Future(executor=self)

    def _schedule(self, task: Task[Any]) -> None:
        with self._tasks_lock:
            self._ready_tasks.append(task)
        self.wake()

    def wake(self) -> None:
        """Make a waiting ``wait_for_ready_callbacks`` look again (something changed)."""
        participant = self._context.participant
        if participant is not None:
            participant.notify()

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        """Stop spinning and wait for running callbacks; False if they outlast the timeout."""
        self._is_shutdown = True
        self.wake()
        wait = None if timeout_sec is None or timeout_sec < 0 else timeout_sec
        with self._work_done:
            finished = self._work_done.wait_for(lambda: self._work == 0, wait)
        with self._nodes_lock:
            for node in list(self._nodes):
                if node.executor is self:
                    node.executor = None
            self._nodes.clear()
        self._cb_iter = None
        return finished

    def __enter__(self) -> Executor:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.shutdown()

    # --- spinning ----------------------------------------------------------------------------

    def _running(self) -> bool:
        return not self._is_shutdown and self._context.ok()

    def spin(self) -> None:
        """Run callbacks until the context shuts down (Ctrl-C) or :meth:`shutdown`."""
        while self._running():
            self.spin_once()

    def spin_once(self, timeout_sec: float | None = None) -> None:
        """Wait for one callback and run it.

        ``timeout_sec`` None or negative waits without limit; 0 does not wait.
        """
        try:
            handler, _, _ = self.wait_for_ready_callbacks(timeout_sec=timeout_sec)
        except _STOPS:
            return
        self._run_handler(handler)

    def spin_some(self, timeout_sec: float = 0.0) -> int:
        """Run every callback ready now, waiting up to ``timeout_sec`` for the first; how many.

        As rclcpp's ``spin_some``: what becomes ready while these run waits for the next call.
        """
        ran = 0
        wait: float | None = timeout_sec
        while True:
            try:
                handler, _, _ = self.wait_for_ready_callbacks(timeout_sec=wait)
            except _STOPS:
                return ran
            handler()
            ran += 1
            error = handler.exception()
            if error is not None:
                raise error
            wait = 0.0

    def spin_until_future_complete(
        self, future: Future[Any], timeout_sec: float | None = None
    ) -> None:
        """Spin until ``future`` is done, the timeout passes, or the context shuts down."""
        future.add_done_callback(lambda _: self.wake())
        forever = timeout_sec is None or timeout_sec < 0
        deadline = None if forever else time.monotonic() + (timeout_sec or 0.0)
        while self._running() and not future.done():
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                return
            self._spin_once_until(future, remaining)

    def spin_once_until_future_complete(
        self, future: Future[Any], timeout_sec: float | None = None
    ) -> None:
        """One :meth:`spin_once`, returning early when ``future`` completes."""
        future.add_done_callback(lambda _: self.wake())
        self._spin_once_until(future, timeout_sec)

    def _spin_once_until(self, future: Future[Any], timeout_sec: float | None) -> None:
        try:
            handler, _, _ = self.wait_for_ready_callbacks(timeout_sec, None, future.done)
        except _STOPS:
            return
        self._run_handler(handler)

    def _run_handler(self, handler: Task[Any]) -> None:
        """Run one handler as :meth:`spin_once` does (a subclass may hand it to a thread)."""
        handler()
        error = handler.exception()
        if error is not None:
            raise error

    # --- waiting for work --------------------------------------------------------------------

    def wait_for_ready_callbacks(self, *args: Any, **kwargs: Any) -> Ready:
        """The next (handler, entity, node) to run; waits for one.

        Arguments (``timeout_sec=None, nodes=None, condition=None``) go to the generator that
        finds ready callbacks; calls with the same arguments go on with the same generator,
        so one wait serves several callbacks.

        Raises:
            TimeoutException: nothing became ready within ``timeout_sec``.
            ShutdownException: the executor was shut down.
            ExternalShutdownException: the context was shut down.
            ConditionReachedException: ``condition()`` became true.
        """
        while True:
            if self._cb_iter is None or self._last_args != args or self._last_kwargs != kwargs:
                self._last_args, self._last_kwargs = args, kwargs
                self._cb_iter = self._wait_for_ready_callbacks(*args, **kwargs)
            try:
                return next(self._cb_iter)
            except StopIteration:
                self._cb_iter = None
            except BaseException:
                self._cb_iter = None
                raise

    def can_execute(self, entity: Any) -> bool:
        """Whether ``entity``'s callback may be offered now (not in flight; its group agrees)."""
        if entity._executor_event:
            return False
        group = entity.callback_group
        return group is None or bool(group.can_execute(entity))

    def _wait_for_ready_callbacks(
        self,
        timeout_sec: float | None = None,
        nodes: Iterable[Node] | None = None,
        condition: Callable[[], bool] | None = None,
    ) -> Generator[Ready, None, None]:
        deadline = (
            None if timeout_sec is None or timeout_sec < 0 else time.monotonic() + timeout_sec
        )
        yielded = False
        waited = False
        while not yielded:
            participant = self._participant()
            changes = None if participant is None else participant.changes
            chosen = self.get_nodes() if nodes is None else list(nodes)
            self._check_stop(condition)
            work = self._collect(chosen)
            for task_or_entity, node in work:
                if isinstance(task_or_entity, Task):
                    if task_or_entity.done():
                        continue
                    yielded = True
                    yield Ready((task_or_entity, task_or_entity.entity, node))
                elif (
                    node is not None
                    and self.can_execute(task_or_entity)
                    and task_or_entity._ready()
                ):
                    yielded = True
                    yield Ready((self._make_handler(task_or_entity, node), task_or_entity, node))
            if yielded:
                return
            if work:
                continue  # what looked ready was taken meanwhile (another thread): look again
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0 and waited:
                raise TimeoutException
            self._answer_lockstep(participant, chosen)
            wait = self._next_timer(chosen)
            if remaining is not None:
                wait = max(0.0, remaining) if wait is None else min(wait, max(0.0, remaining))
            waited = True
            if participant is None:
                time.sleep(0.05 if wait is None else min(wait, 0.05))
                continue

            def ready(nodes_: list[Node] = chosen) -> bool:
                return (
                    not self._running()
                    or bool(self._ready_tasks)
                    or (condition is not None and condition())
                    or self._any_ready(nodes_)
                )

            participant.wait(ready, wait, changes)

    def _check_stop(self, condition: Callable[[], bool] | None) -> None:
        if self._is_shutdown:
            raise ShutdownException
        if not self._context.ok():
            raise ExternalShutdownException
        if condition is not None and condition():
            raise ConditionReachedException

    def _participant(self) -> Participant | None:
        participant = self._context.participant
        return None if participant is None or participant.closed else participant

    def _collect(self, nodes: list[Node]) -> list[tuple[Any, Node | None]]:
        """Tasks to resume and entities whose callback could run, in rclpy's order per node."""
        work: list[tuple[Any, Node | None]] = []
        if self._ready_tasks:
            with self._tasks_lock:
                tasks, self._ready_tasks = self._ready_tasks, deque()
            for task in tasks:
                node = task.node
                if node is None or node in nodes:
                    work.append((task, node))
                else:
                    with self._tasks_lock:
                        self._ready_tasks.append(task)
        can_execute = self.can_execute
        for node in nodes:
            for entity in node._entities():
                if not entity._executor_event and entity._ready() and can_execute(entity):
                    work.append((entity, node))
        return work

    def _any_ready(self, nodes: list[Node]) -> bool:
        can_execute = self.can_execute
        for node in nodes:
            for entity in node._entities():
                if not entity._executor_event and entity._ready() and can_execute(entity):
                    return True
        return False

    def _next_timer(self, nodes: list[Node]) -> float | None:
        """Seconds until the next wall-time timer of these nodes that could run is due."""
        soonest: float | None = None
        for node in nodes:
            for timer in node.timers:
                if timer.clock.ros_time_is_active or not self.can_execute(timer):
                    continue  # sim-time timers are woken by /clock arriving
                until = timer.time_until_next_call()
                if until is not None:
                    seconds = max(0.0, until / 1e9)
                    soonest = seconds if soonest is None else min(soonest, seconds)
        return soonest

    # --- running one callback ----------------------------------------------------------------

    def _make_handler(self, entity: Any, node: Node) -> Task[Any]:
        """The task that takes ``entity``'s data and runs its callback (once)."""
        entity._executor_event = True  # not offered again until taken
        handler: Task[Any] = Task(self._execute, (entity, node), executor=self)
        handler.entity, handler.node = entity, node
        return handler

    def _execute(self, entity: Any, node: Node) -> Any:
        group = None if entity._ungrouped else entity.callback_group
        if self._is_shutdown or (group is not None and not group.beginning_execution(entity)):
            entity._executor_event = False
            self.wake()
            return None
        with self._work_done:
            self._work += 1
        try:
            work = entity._take()
        finally:
            entity._executor_event = False
            self.wake()  # it may be offered again (a reentrant group)
        if work is None:
            self._end(entity, group)
            return None
        if entity._is_timer:
            self._timers_ran += 1
        try:
            result = work()
        except Exception as err:
            self._end(entity, group)
            node._callback_failed(err, entity._what)
            return None
        except BaseException:
            self._end(entity, group)
            raise
        if inspect.iscoroutine(result):
            return self._finish(result, entity, node, group)
        self._end(entity, group)
        return result

    async def _finish(
        self, pending: Coroutine[Any, Any, Any], entity: Any, node: Node, group: Any
    ) -> Any:
        """Await a coroutine callback; the group stays taken until it returns."""
        try:
            return await pending
        except Exception as err:
            node._callback_failed(err, entity._what)
            return None
        finally:
            self._end(entity, group)

    def _end(self, entity: Any, group: Any) -> None:
        if group is not None:
            group.ending_execution(entity)
        with self._work_done:
            self._work -= 1
            if self._work <= 0:
                self._work = 0
                self._work_done.notify_all()
        self.wake()  # a mutually exclusive group is free again

    # --- lock-step ---------------------------------------------------------------------------

    def _answer_lockstep(self, participant: Participant | None, nodes: list[Node]) -> None:
        """Before waiting: answer a lock-stepped simulator whose messages were handled.

        The answer follows the timers the new ``/clock`` made due (see
        :mod:`rosl.node.lockstep`).
        """
        if participant is None or not self.answers_lockstep:
            return
        answerer = participant.answerer or participant.answer_lockstep()
        if answerer.seen:
            answerer.answer(self._next_sim_wakeup(nodes), self._timers_ran > 0)
            self._timers_ran = 0

    def _next_sim_wakeup(self, nodes: list[Node]) -> int:
        """The earliest sim-time timer deadline (ns), -1 when no sim-time timer is armed."""
        soonest = -1
        for node in nodes:
            for timer in node.timers:
                if timer.clock.ros_time_is_active and not timer.is_canceled():
                    due = timer.clock.now_ns() + (timer.time_until_next_call() or 0)
                    soonest = due if soonest < 0 else min(soonest, due)
        return soonest


class SingleThreadedExecutor(Executor):
    """Runs callbacks on the thread that spins (rclpy's default)."""


def _default_threads() -> int:
    try:
        return len(os.sched_getaffinity(0)) or 2
    except (AttributeError, OSError):
        return os.cpu_count() or 2


class MultiThreadedExecutor(Executor):
    """Runs callbacks in a pool of ``num_threads`` threads (default: the usable CPUs).

    Callback groups decide what may run together: a node's default group is mutually
    exclusive, a ``ReentrantCallbackGroup`` lets its callbacks overlap.
    """

    def __init__(self, num_threads: int | None = None, *, context: Context | None = None) -> None:
        super().__init__(context=context)
        self.num_threads = num_threads or _default_threads()
        self._pool = ThreadPoolExecutor(self.num_threads, thread_name_prefix="rosl-executor")
        self._handlers: list[Task[Any]] = []
        self._handlers_lock = threading.Lock()

    def _run_handler(self, handler: Task[Any]) -> None:
        handler.add_done_callback(lambda _: self.wake())
        self._pool.submit(handler)
        with self._handlers_lock:
            self._handlers.append(handler)
            failed = [h for h in self._handlers if h.done() and h.exception() is not None]
            self._handlers = [h for h in self._handlers if not h.done()]
        if failed:
            error = failed[0].exception()
            assert error is not None
            raise error

    def shutdown(self, timeout_sec: float | None = None, *, wait_for_threads: bool = True) -> bool:
        """Stop spinning, wait for running callbacks, and end the pool's threads."""
        finished = super().shutdown(timeout_sec)
        self._pool.shutdown(wait=wait_for_threads)
        return finished


__all__ = [
    "ConditionReachedException",
    "Executor",
    "ExternalShutdownException",
    "Future",
    "MultiThreadedExecutor",
    "ShutdownException",
    "SingleThreadedExecutor",
    "Task",
    "TimeoutException",
]
