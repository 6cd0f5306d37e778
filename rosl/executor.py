"""Executors: run the callbacks of the nodes added to them, as rclpy's do.

Deliveries wait in their entity's queue (a subscription's, a service's, a client's; see
:meth:`rosl.node.participant.Participant.poll`). One look at the entities of this
executor's nodes only — queued deliveries, due timers, triggered guard conditions, ready
waitables, tasks to resume — finds everything whose callback group lets it run, and hands
those out one at a time before looking again; when nothing is ready the executor waits on the
participant (which polls the transport) until something is, or the next timer is due.
``SingleThreadedExecutor`` runs each callback on the spinning thread, ``MultiThreadedExecutor``
in a pool of threads, and a custom executor decides (rclpy's API: subclass :class:`Executor`,
call ``wait_for_ready_callbacks`` and run or hand off the handler task it returns). rosl's own
housekeeping (a node's name check) never counts as ``spin_once``'s one callback.

Two choices differ from rclpy, both to remove its classic deadlocks: a client's response
completes its future whatever the client's callback group is doing (so a callback in a
mutually exclusive group may ``await client.call_async(...)``), and ``Client.call`` inside a
callback reads its response itself. A coroutine callback suspended on a future resumes when
the future completes, not by polling.
"""

from __future__ import annotations

import functools
import os
import signal
import threading
import time
from collections import deque
from types import CoroutineType
from typing import TYPE_CHECKING, Any

from rosl.node.callback_groups import MutuallyExclusiveCallbackGroup, held_groups
from rosl.node.clock import ClockType
from rosl.node.task import Future, Task, current_task

if TYPE_CHECKING:
    from collections.abc import Callable, Coroutine, Iterable
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
        self._nodes: tuple[Node, ...] = ()  # replaced, never changed in place: read lock-free
        self._nodes_lock = threading.RLock()
        self._ready_tasks: deque[Task[Any]] = deque()
        self._tasks_lock = threading.Lock()
        self._is_shutdown = False
        self._told_external = False  # spin_once returned once after the context shut down
        self._batch: deque[tuple[Any, Node | None]] = deque()  # found ready, not handed out
        self._turn = 0  # rotates the order of what one look finds (see _collect)
        self._rotate = False  # only with threads: one thread runs a whole look in order
        self._timers_ran = 0  # timer callbacks since the last lock-step answer
        self.answers_lockstep = True  # rosl: answer lock-stepped simulators when idle
        self._work = 0  # callbacks running (shutdown waits for them)
        self._work_lock = threading.Lock()
        self._inside = threading.local()  # depth: callbacks of this executor on this thread
        # (the participant's `changes`, the nodes) when a wait ended at its timeout with nothing
        # changed: until `changes` moves, only time does, and a look need only ask the timers
        self._quiet: tuple[int, tuple[Node, ...]] | None = None
        self._fast: Any = None  # the timer the last timers-only look handed out
        self._fast_thread = 0  # the thread that looked
        self._looks = 0  # whole looks and waits so far (a nested spin in a callback counts)
        self._fast_looks = 0  # ... when the timer was handed out
        self._looking = 0  # threads inside _next_work
        self._idle_at: int | None = None  # the participant's changes when a look found nothing
        self._one: tuple[Any, Callable[[], Any]] | None = None  # (a timer, its _one_timer look)
        # spin_once may take the timers-only way (_spin_timers): callbacks run on this thread
        # the timers-only looks (_due_timer, _one_timer) do not call can_execute: not for an
        # executor that decides it itself
        cls = type(self)
        self._timers_only = cls.can_execute is Executor.can_execute
        self._plain = self._timers_only and (cls._run, cls._next_work) == (
            Executor._run,
            Executor._next_work,
        )
        # a timers-only look handed out a due timer without polling the transport first (no
        # wait came before it): the next such look polls, so a timer that overruns its period
        # cannot keep what arrives from being read
        self._unpolled = False

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
            self._nodes = (*self._nodes, node)
        node.executor = self
        self.wake()
        return True

    def remove_node(self, node: Node) -> None:
        """Stop running ``node``'s callbacks."""
        with self._nodes_lock:
            if node not in self._nodes:
                return
            self._nodes = tuple(n for n in self._nodes if n is not node)
        if node.executor is self:
            node.executor = None
        self.wake()

    def get_nodes(self) -> list[Node]:
        """The nodes this executor runs."""
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
        participant = self._context.participant  # (Context.wake_executors, one call less:
        if participant is not None:  # twice per callback)
            participant.notify()

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        """Stop spinning and wait for running callbacks; False if they outlast the timeout."""
        self._is_shutdown = True
        self.wake()
        own = getattr(self._inside, "depth", 0)  # called from a callback: do not wait for it
        forever = timeout_sec is None or timeout_sec < 0
        deadline = time.monotonic() + (0.0 if forever else (timeout_sec or 0.0))
        while self._work > own and (forever or time.monotonic() < deadline):
            time.sleep(0.005)
        finished = self._work <= own
        with self._nodes_lock:
            nodes, self._nodes = self._nodes, ()
            for node in nodes:
                if node.executor is self:
                    node.executor = None
        self._batch.clear()
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
        """Run callbacks until the context shuts down (Ctrl-C) or :meth:`shutdown`.

        Returns quietly then (rosl's Ctrl-C: the cleanup after ``spin`` runs), also for
        custom executors whose ``spin_once`` lets the shutdown exceptions out.
        """
        while self._running():
            try:
                self.spin_once()
            except (ShutdownException, ExternalShutdownException):
                return

    def spin_once(self, timeout_sec: float | None = None) -> None:
        """Wait for one callback and run it.

        ``timeout_sec`` None or negative waits without limit; 0 does not wait.
        """
        forever = timeout_sec is None or timeout_sec < 0
        deadline = None if forever else time.monotonic() + (timeout_sec or 0.0)
        remaining = None if forever else timeout_sec
        if self._quiet is not None and self._plain:
            if self._spin_timers(deadline):
                return
            remaining = None if deadline is None else max(0.0, deadline - time.monotonic())
        while True:
            try:
                item, node = self._next_work(remaining)
            except ExternalShutdownException:
                self._after_external_shutdown()
                return
            except _STOPS:
                return
            self._run(item, node)
            if not item._internal:
                return  # rosl's own housekeeping does not count as the one callback
            remaining = None if deadline is None else max(0.0, deadline - time.monotonic())

    def _spin_timers(self, deadline: float | None) -> bool:
        """``spin_once`` for nodes that only wait for their timers; False: look the usual way.

        Taken when the last wait ended at its timeout with nothing changed (``_quiet``), so
        only time has moved: the look asks the timers, the wait polls the transport, and the
        due timer runs here (a publisher's 1 kHz timer asks a thousand times a second, and
        in many processes on few cores every step counts). It gives up to the usual look at
        once when anything else may be ready: a change the participant counts, queued work,
        a callback running, a shutdown, a lock-stepped simulator to answer. True when done:
        a user's timer ran, or the time was up.
        """
        quiet = self._quiet
        context = self._context
        participant = context.participant
        if (
            quiet is None
            or participant is None
            or participant.changes != quiet[0]
            or self._nodes is not quiet[1]
            or self._batch
            or self._ready_tasks
            or self._work
            or self._is_shutdown
            or participant.closed
            or not context.ok()
        ):
            return False
        if self.answers_lockstep:
            answerer = participant.answerer
            if answerer is None or answerer.seen:
                return False
        changes, nodes = quiet
        if len(nodes) == 1 and len(nodes[0].timers) == 1:  # a publisher's: its timer alone
            one = self._one
            if one is None or one[0] is not nodes[0].timers[0]:
                one = self._one = (nodes[0].timers[0], self._one_timer(*nodes, *nodes[0].timers))
            look = one[1]
        else:
            look = functools.partial(self._due_timer, nodes)
        waited = False
        self._looking += 1
        try:
            while True:
                due = look()
                if isinstance(due, tuple):
                    if not self._polled_first(waited, participant, changes):
                        self._take_back(due[0])
                        return False
                    break
                if due is None:  # no wall-time timer: the usual look waits without one
                    return False
                if deadline is not None:
                    remaining = deadline - time.monotonic()
                    if remaining <= 0 and waited:
                        return True
                    due = min(due, max(0.0, remaining))
                waited = True
                self._looks += 1
                if participant.wait_change(due, changes):
                    self._quiet = None
                    return False
        finally:
            self._looking -= 1
        timer, node = due
        result = self._execute(timer, node)
        if isinstance(result, CoroutineType):  # (as _run)
            task: Task[Any] = Task(_given, (result,), executor=self)
            task.entity, task.node = timer, node
            task()
        return not timer._internal  # rosl's housekeeping: spin_once goes on to look for one

    def _one_timer(self, node: Node, timer: Any) -> Callable[[], tuple[Any, Node] | float | None]:
        """:meth:`_due_timer` for one node with one timer (a publisher): its clock read directly."""
        clock = timer.clock
        group = None if timer._ungrouped else timer.callback_group
        now_ns = time.monotonic_ns if clock.clock_type is ClockType.STEADY_TIME else time.time_ns
        found = (timer, node)

        def look() -> tuple[Any, Node] | float | None:
            if (
                timer._canceled
                or timer._executor_event
                or clock._sim_ns is not None  # (sim-time timers are woken by /clock)
                or (group is not None and not group.can_execute(timer))
            ):
                return None
            until: int = timer._next_call_ns - now_ns()
            if until > 0:
                return until / 1e9
            self._hand_out(timer)
            return found

        return look

    def _hand_out(self, timer: Any) -> None:
        """Mark a timer a timers-only look found due as in flight, and remember who looked."""
        timer._executor_event = True  # not offered again until taken
        self._fast = timer
        self._fast_thread = threading.get_ident()
        self._fast_looks = self._looks

    def _take_back(self, timer: Any) -> None:
        """Undo :meth:`_hand_out`: the timer was not given to run after all."""
        timer._executor_event = False
        self._fast = None

    def _polled_first(self, waited: bool, participant: Participant, changes: int) -> bool:
        """Before a timers-only look hands out a due timer: False when a poll found news.

        A look that waited polled the transport. One that did not (the timer was due at once)
        polls first when the look before it did not either: a timer whose callback outlasts
        its period is always due, and would otherwise keep every message, request and response
        in the socket. Costs nothing while the timer keeps its period. When the poll read
        something, the caller lets the usual look decide (``_quiet`` is then cleared).
        """
        if waited:
            self._unpolled = False
            return True
        if not self._unpolled:
            self._unpolled = True
            return True
        self._unpolled = False
        if participant.wait_change(0.0, changes):
            self._quiet = None
            return False
        return True

    def _after_external_shutdown(self) -> None:
        """``spin_once`` after the context was shut down: return once, then end the loop.

        The first call returns quietly, so ``while rclpy.ok(): spin_once()`` ends as usual.
        A loop that calls again (``while True``) would spin hot for ever; as with rclpy, where
        Ctrl-C raises out of ``spin_once``, it gets KeyboardInterrupt after Ctrl-C (else
        ExternalShutdownException).
        """
        if not self._told_external:
            self._told_external = True
            return
        if self._context.signalled == signal.SIGINT:
            raise KeyboardInterrupt
        raise ExternalShutdownException

    def spin_some(self, timeout_sec: float = 0.0) -> int:
        """Run every callback ready now, waiting up to ``timeout_sec`` for the first; how many.

        As rclcpp's ``spin_some``: what becomes ready while these run waits for the next call.
        """
        participant = self._context.participant
        if not timeout_sec and participant is not None and self._still_idle(participant):
            return 0
        before = None if participant is None else participant.changes
        ran = 0
        wait: float | None = timeout_sec
        while self._spin_one(wait):
            ran += 1
            wait = 0.0
        if not ran and participant is not None and participant.changes == before:
            self._idle_at = before  # nothing was ready, and nothing has changed since the look
        return ran

    def _still_idle(self, participant: Participant) -> bool:
        """Whether a ``spin_some`` would find nothing: as at its last empty look, with no news.

        Everything but time that makes an entity ready or runnable says so through the
        participant's ``changes`` (see :meth:`_next_work`); so when they have not moved since a
        look that found nothing, only the due timers and the transport need a look: what it
        holds is dispatched now, and any delivery moves ``changes`` again. A quiet look of a
        bus-driven node (the simulator's, once a millisecond) costs a poll, not a walk over
        every entity.
        """
        answerer = participant.answerer  # an idle look answers simulators that it has heard
        if (
            self._idle_at != participant.changes
            or self._batch
            or self._ready_tasks
            or self._is_shutdown
            or participant.closed
            or not self._context.ok()
            or (self.answers_lockstep and (answerer is None or answerer.seen))
        ):
            return False
        for node in self._nodes:
            if node.waitables:  # their readiness is their own: look at them the usual way
                return False
            for timer in node.timers:
                if timer._ready() and self.can_execute(timer):
                    return False
        participant.poll(0.0)
        return self._idle_at == participant.changes

    def spin_until_future_complete(
        self, future: Future[Any], timeout_sec: float | None = None
    ) -> None:
        """Spin until ``future`` is done, the timeout passes, or the context shuts down.

        A Ctrl-C that ends the wait before ``future`` is done raises KeyboardInterrupt, as in
        rclpy: the code after it reads ``future.result()``, which has nothing to give.
        """
        future.add_done_callback(lambda _: self.wake())
        forever = timeout_sec is None or timeout_sec < 0
        deadline = None if forever else time.monotonic() + (timeout_sec or 0.0)
        while self._running() and not future.done() and not future.cancelled():
            remaining = None if deadline is None else max(0.0, deadline - time.monotonic())
            self._spin_one(remaining, future.done)
            if deadline is not None and time.monotonic() >= deadline:
                return
        if not future.done() and self._context.signalled == signal.SIGINT:
            raise KeyboardInterrupt

    def spin_once_until_future_complete(
        self, future: Future[Any], timeout_sec: float | None = None
    ) -> None:
        """One :meth:`spin_once`, returning early when ``future`` completes."""
        future.add_done_callback(lambda _: self.wake())
        self._spin_one(timeout_sec, future.done)

    def _spin_one(
        self, timeout_sec: float | None, condition: Callable[[], bool] | None = None
    ) -> bool:
        """Wait for one callback (or ``condition()``) and run it; whether one ran."""
        try:
            item, node = self._next_work(timeout_sec, None, condition)
        except _STOPS:
            return False
        self._run(item, node)
        return True

    def _run(self, item: Any, node: Node | None) -> None:
        """Run a task step or an entity's callback on this thread (subclasses may not)."""
        if isinstance(item, Task):
            item()
            error = item.exception()
            if error is not None:
                raise error
            return
        assert node is not None
        result = self._execute(item, node)
        if isinstance(result, CoroutineType):  # a coroutine callback: go on as a task
            task: Task[Any] = Task(_given, (result,), executor=self)
            task.entity, task.node = item, node
            task()

    # --- waiting for work --------------------------------------------------------------------

    def wait_for_ready_callbacks(
        self,
        timeout_sec: float | None = None,
        nodes: Iterable[Node] | None = None,
        condition: Callable[[], bool] | None = None,
    ) -> Ready:
        """The next (handler, entity, node) to run, waiting up to ``timeout_sec`` for one.

        The handler is a :class:`Task`: calling it takes the entity's data and runs its
        callback. One look at the nodes finds every ready entity; later calls hand them out
        before looking again.

        Raises:
            TimeoutException: nothing became ready within ``timeout_sec``.
            ShutdownException: the executor was shut down.
            ExternalShutdownException: the context was shut down.
            ConditionReachedException: ``condition()`` became true.
        """
        item, node = self._next_work(timeout_sec, nodes, condition)
        if isinstance(item, Task):
            return Ready((item, item.entity, node))
        assert node is not None
        handler: Task[Any] = Task(self._execute, (item, node), executor=self)
        handler.entity, handler.node = item, node
        return Ready((handler, item, node))

    def can_execute(self, entity: Any) -> bool:
        """Whether ``entity``'s callback may be offered now (not in flight; its group agrees)."""
        if entity._executor_event:
            return False
        group = entity.callback_group
        return group is None or entity._ungrouped or bool(group.can_execute(entity))

    def _next_work(
        self,
        timeout_sec: float | None,
        nodes: Iterable[Node] | None = None,
        condition: Callable[[], bool] | None = None,
    ) -> tuple[Any, Node | None]:
        """The next task to resume, or entity to run (marked in flight); waits for one."""
        self._looking += 1
        try:
            return self._look(timeout_sec, nodes, condition)
        finally:
            self._looking -= 1

    def _look(
        self,
        timeout_sec: float | None,
        nodes: Iterable[Node] | None,
        condition: Callable[[], bool] | None,
    ) -> tuple[Any, Node | None]:
        deadline = (
            None if timeout_sec is None or timeout_sec < 0 else time.monotonic() + timeout_sec
        )
        only = None if nodes is None else tuple(nodes)
        batch = self._batch
        context = self._context
        waited = False
        while True:
            if self._is_shutdown:
                raise ShutdownException
            if not context.ok():
                raise ExternalShutdownException
            if condition is not None and condition():
                raise ConditionReachedException
            while batch:
                item, node = batch.popleft()
                if node is not None and node not in (self._nodes if only is None else only):
                    if isinstance(item, Task):
                        self._schedule(item)  # for another call
                    continue
                if isinstance(item, Task):
                    if not (item.done() or item.cancelled()):
                        return item, node
                elif self.can_execute(item) and item._ready():
                    item._executor_event = True  # not offered again until taken
                    return item, node
            participant = context.participant
            if participant is not None and participant.closed:
                participant = None
            changes = None if participant is None else participant.changes
            chosen = self._nodes if only is None else only
            quiet = self._quiet
            if (
                quiet is not None
                and changes == quiet[0]
                and chosen is quiet[1]
                and self._timers_only
            ):
                # the wait timed out with nothing changed: only time moved (all else that
                # becomes ready or runnable says so through participant.notify()), so the
                # first due timer is the one to run; the next call looks at the rest
                due = self._due_timer(chosen)
                if isinstance(due, tuple):
                    if participant is None or self._polled_first(waited, participant, changes):
                        return due
                    self._take_back(due[0])  # something arrived: look at it all
                    continue
                wait = due
            elif self._collect(chosen, batch):
                item, node = batch[0]
                if not isinstance(item, Task):  # this look found it ready and runnable
                    if item._is_timer and not waited and changes is not None:
                        # always due (its callback outlasts its period): what arrives must
                        # still be read; the next look collects it
                        assert participant is not None  # (changes was read from it)
                        self._polled_first(False, participant, changes)
                    batch.popleft()
                    item._executor_event = True  # not offered again until taken
                    return item, node
                continue
            else:
                wait = self._next_timer(chosen)
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0 and waited:
                raise TimeoutException
            if participant is not None and self.answers_lockstep and not self._work:
                answerer = participant.answerer
                if answerer is None or answerer.seen:
                    self._answer_lockstep(participant, chosen)  # (after every running callback)
            if remaining is not None:
                wait = max(0.0, remaining) if wait is None else min(wait, max(0.0, remaining))
            waited = True
            if participant is None:
                time.sleep(0.05 if wait is None else min(wait, 0.05))
                continue
            assert changes is not None  # (read from the participant)
            self._looks += 1
            # ends on any change since `changes` was read, or at `wait`: then this loop looks
            if wait is None:
                changed = participant.wait(_never, wait, changes)
            else:
                changed = participant.wait_change(wait, changes)
            self._quiet = None if changed else (changes, chosen)

    def _collect(
        self, nodes: tuple[Node, ...], into: deque[tuple[Any, Node | None]] | None
    ) -> bool:
        """Queue in ``into`` the tasks to resume and the entities whose callback could run.

        Entities come in rclpy's order per node. With ``into`` None, only say whether there
        are any.
        """
        self._looks += 1
        found = False
        if self._ready_tasks:
            if into is None:
                return True
            with self._tasks_lock:
                tasks, self._ready_tasks = self._ready_tasks, deque()
            for task in tasks:
                node = task.node
                if node is None or node in nodes:
                    into.append((task, node))
                    found = True
                else:
                    with self._tasks_lock:
                        self._ready_tasks.append(task)
        ready: list[tuple[Any, Node | None]] = []
        can_execute = self.can_execute
        for node in nodes:
            for entity in node._entities():
                if entity._ready() and can_execute(entity):
                    if into is None:
                        return True
                    ready.append((entity, node))
        if self._rotate and len(ready) > 1:  # threads: start each look one further, so when
            # a busy group lets only one of them run, the others get their turn
            self._turn = turn = (self._turn + 1) % len(ready)
            ready = ready[turn:] + ready[:turn]
        if ready and into is not None:
            into.extend(ready)
            found = True
        return found

    def _due_timer(self, nodes: tuple[Node, ...]) -> tuple[Any, Node] | float | None:
        """The first due timer that can run (marked in flight), else :meth:`_next_timer`.

        One pass for both: a node that only has timers asks this at every wake-up.
        """
        soonest: int | None = None
        for node in nodes:
            for timer in node.timers:
                if timer._canceled or timer._executor_event:
                    continue
                clock = timer.clock
                until = timer._next_call_ns - clock.now_ns()
                group = timer.callback_group
                if group is not None and not timer._ungrouped and not group.can_execute(timer):
                    continue
                if until <= 0:
                    self._hand_out(timer)
                    return timer, node
                if clock._sim_ns is None and (soonest is None or until < soonest):
                    soonest = until  # (sim-time timers are woken by /clock arriving)
        return None if soonest is None else soonest / 1e9

    def _next_timer(self, nodes: tuple[Node, ...]) -> float | None:
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

    def _execute(self, entity: Any, node: Node) -> Any:
        group = None if entity._ungrouped else entity.callback_group
        if self._is_shutdown or (group is not None and not group.beginning_execution(entity)):
            entity._executor_event = False
            self.wake()
            return None
        with self._work_lock:
            self._work += 1
        inside = self._inside
        inside.depth = getattr(inside, "depth", 0) + 1
        try:
            try:
                work = entity._take()
            finally:
                entity._executor_event = False
                if not isinstance(group, MutuallyExclusiveCallbackGroup) and (
                    self._fast is not entity or threading.get_ident() != self._fast_thread
                ):
                    self.wake()  # it may be offered again (else: the group is free at _end)
            if work is None:
                self._end(entity, group)
                return None
            if entity._is_timer:
                self._timers_ran += 1
            if group is None:
                result = work()
            else:  # (a drain of the group's subscription on this thread runs inside it)
                held = held_groups()
                held.append(group)
                try:
                    result = work()
                finally:
                    held.pop()
        except Exception as err:
            self._end(entity, group)
            node._callback_failed(err, entity._what)
            return None
        except BaseException:
            self._end(entity, group)
            raise
        finally:
            inside.depth -= 1
        if isinstance(result, CoroutineType):
            return self._finish(result, entity, node, group)
        self._end(entity, group)
        return result

    async def _finish(
        self, pending: Coroutine[Any, Any, Any], entity: Any, node: Node, group: Any
    ) -> Any:
        """Await a coroutine callback; the group stays taken until it returns."""
        task = current_task()  # the handler task driving this coroutine
        if task is not None:
            task.holds = group
        try:
            return await pending
        except Exception as err:
            node._callback_failed(err, entity._what)
            return None
        finally:
            if task is not None:
                task.holds = None
            self._end(entity, group)

    def _end(self, entity: Any, group: Any) -> None:
        if group is not None:
            group.ending_execution(entity)
        with self._work_lock:
            self._work -= 1
            idle = not self._work
        if self._fast is entity:
            self._fast = None
            participant = self._context.participant
            if (
                idle
                and self._looks == self._fast_looks
                and not self._looking
                and participant is not None
                and participant.unwatched()
                and threading.get_ident() == self._fast_thread
            ):
                # a timer a timers-only look handed out, run by the thread that looked, with
                # nothing else running, nobody looking or waiting, and no look since (a
                # nested spin in its callback may have passed over what its group held):
                # the group is as free as at that look, so the next look may still ask only
                # the timers (what its callback changed, it notified)
                return
        self.wake()  # a mutually exclusive group is free again

    # --- lock-step ---------------------------------------------------------------------------

    def _answer_lockstep(self, participant: Participant, nodes: tuple[Node, ...]) -> None:
        """Before waiting: answer a lock-stepped simulator whose messages were handled.

        The answer follows the timers the new ``/clock`` made due (see
        :mod:`rosl.node.lockstep`).
        """
        answerer = participant.answerer or participant.answer_lockstep()
        if answerer.seen:
            answerer.answer(self._next_sim_wakeup(nodes), self._timers_ran > 0)
            self._timers_ran = 0

    def _next_sim_wakeup(self, nodes: tuple[Node, ...]) -> int:
        """The earliest sim-time timer deadline (ns), -1 when no sim-time timer is armed."""
        soonest = -1
        for node in nodes:
            for timer in node.timers:
                if timer.clock.ros_time_is_active and not timer.is_canceled():
                    due = timer.clock.now_ns() + (timer.time_until_next_call() or 0)
                    soonest = due if soonest < 0 else min(soonest, due)
        return soonest


def _given(value: Any) -> Any:
    return value


def _never() -> bool:
    """The ``ready`` of a participant wait given ``since`` (it is not asked)."""
    return False


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
        if num_threads is not None and num_threads < 1:
            from rosl.node.errors import ThreadCountError

            raise ThreadCountError(
                f"MultiThreadedExecutor needs num_threads >= 1, got {num_threads}"
            )
        self.num_threads = num_threads or _default_threads()
        self._rotate = True
        from concurrent.futures import ThreadPoolExecutor  # (and logging): not for every CLI

        self._pool = ThreadPoolExecutor(self.num_threads, thread_name_prefix="rosl-executor")
        self._handlers: list[Task[Any]] = []
        self._handlers_lock = threading.Lock()

    def _run(self, item: Any, node: Node | None) -> None:
        if isinstance(item, Task):
            handler = item
        else:
            assert node is not None
            handler = Task(self._execute, (item, node), executor=self)
            handler.entity, handler.node = item, node
        with self._handlers_lock:
            new = handler not in self._handlers  # a suspended task comes back: once is enough
            if new:
                self._handlers.append(handler)
        if new:
            handler.add_done_callback(lambda _: self.wake())
        self._pool.submit(handler)
        with self._handlers_lock:
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
