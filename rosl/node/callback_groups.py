"""Callback groups: which of a node's callbacks may run at the same time (rclpy's classes).

An executor asks an entity's group ``can_execute`` before offering its callback, and
``beginning_execution`` / ``ending_execution`` around running it; a custom group subclasses
:class:`CallbackGroup` and decides all three. Every node has a mutually exclusive default
group. Entities are kept by weak reference, as in rclpy.

rosl also remembers which groups the callbacks running on a thread hold (:func:`holding`,
:func:`held_here`): a blocking wait of rosl's own that runs a subscription's callbacks itself
(:meth:`rosl.node.subscription.Subscription.drain`) takes the group as an executor would, or
runs them inside the callback of that group which is waiting.
"""

from __future__ import annotations

import contextlib
import threading
import weakref
from functools import partial
from typing import TYPE_CHECKING, Any

from rosl.node.task import current_task

if TYPE_CHECKING:
    from collections import deque
    from collections.abc import Callable, Iterator

    from rosl.bus.wire import Delivery


class CallbackGroup:
    """The base of callback groups: remembers its entities; subclasses decide execution."""

    def __init__(self) -> None:
        self.entities: set[weakref.ref[Any]] = set()

    def add_entity(self, entity: Any) -> None:
        """Make ``entity`` (a subscription, timer, service, client, guard condition) a member."""
        self.entities.add(weakref.ref(entity))

    def has_entity(self, entity: Any) -> bool:
        """Whether ``entity`` belongs to this group."""
        return weakref.ref(entity) in self.entities

    def can_execute(self, entity: Any) -> bool:
        """Whether a callback of ``entity`` could start now."""
        raise NotImplementedError

    def beginning_execution(self, entity: Any) -> bool:
        """Claim the right to run ``entity``'s callback now; False when the group refuses."""
        raise NotImplementedError

    def ending_execution(self, entity: Any) -> None:
        """``entity``'s callback finished."""
        raise NotImplementedError


class ReentrantCallbackGroup(CallbackGroup):
    """Its callbacks may run at the same time, also several of one entity."""

    def can_execute(self, entity: Any) -> bool:
        """Always."""
        return True

    def beginning_execution(self, entity: Any) -> bool:
        """Always granted."""
        return True

    def ending_execution(self, entity: Any) -> None:
        """Nothing to release."""


class MutuallyExclusiveCallbackGroup(CallbackGroup):
    """At most one of its callbacks runs at any time."""

    def __init__(self) -> None:
        super().__init__()
        self._active: Any = None
        self._lock = threading.Lock()

    def can_execute(self, entity: Any) -> bool:
        """Whether none of the group's callbacks is running."""
        return self._active is None

    def beginning_execution(self, entity: Any) -> bool:
        """Take the group for ``entity`` if it is free."""
        with self._lock:
            if self._active is None:
                self._active = entity
                return True
            return False

    def ending_execution(self, entity: Any) -> None:
        """Free the group."""
        with self._lock:
            if self._active is entity:
                self._active = None


_held = threading.local()  # .groups: the groups of the callbacks running on this thread


def held_groups() -> list[CallbackGroup]:
    """This thread's stack of the groups its running callbacks hold (push, run, pop)."""
    try:
        groups: list[CallbackGroup] = _held.groups  # (per callback: no getattr with a default)
    except AttributeError:
        groups = _held.groups = []
    return groups


@contextlib.contextmanager
def holding(group: CallbackGroup | None) -> Iterator[None]:
    """Note that a callback of ``group`` runs on this thread (the group was taken for it)."""
    if group is None:
        yield
        return
    groups = held_groups()
    groups.append(group)
    try:
        yield
    finally:
        groups.pop()


def held_here(group: CallbackGroup) -> bool:
    """Whether a callback of ``group`` is running on this thread (plain or awaiting)."""
    if group in getattr(_held, "groups", ()):
        return True
    task = current_task()  # a coroutine callback keeps its group taken across its awaits
    return task is not None and task.holds is group


class Executable:
    """What executors need of an entity (subscription, timer, service, client, guard, waitable).

    ``_ready()`` says whether it has work; ``_take()`` takes one piece of it and returns the
    call that does it (None: nothing to do after all). ``_executor_event`` is set while an
    executor's handler for it is on its way, so it is not offered twice.
    """

    callback_group: CallbackGroup | None = None
    _executor_event = False
    _ungrouped = False  # taken whatever its group is doing (clients: completing a future)
    _is_timer = False
    _internal = False  # rosl's housekeeping (spin_once goes on to a callback of the user's)
    _what = "callback"  # how an exception in its callback is introduced

    def _join(self, group: CallbackGroup | None) -> None:
        """Belong to ``group`` (None: to none)."""
        self.callback_group = group
        if group is not None:
            group.add_entity(self)

    def _ready(self) -> bool:
        raise NotImplementedError

    def _take(self) -> Callable[[], Any] | None:
        raise NotImplementedError


class Queued(Executable):
    """An entity whose work is deliveries waiting in its ``_queue`` (filled by ``deliver``)."""

    _queue: deque[Delivery]

    def _ready(self) -> bool:
        return bool(self._queue)

    def _queue_in(self, queue: deque[Delivery]) -> None:
        """Make ``queue`` the entity's queue.

        Its ``_ready`` then calls ``bool`` on it with no Python frame in between (a C call):
        an executor asks every entity of its nodes at every look.
        """
        self._queue = queue
        self._ready = partial(bool, queue)  # type: ignore[method-assign]

    @property
    def queue_limit(self) -> int | None:
        """How many deliveries its queue holds before the oldest goes (None: no bound)."""
        return self._queue.maxlen

    def _pop(self) -> Delivery | None:
        """The oldest queued delivery (None: another thread took it)."""
        try:
            return self._queue.popleft()
        except IndexError:
            return None


__all__ = [
    "CallbackGroup",
    "Executable",
    "MutuallyExclusiveCallbackGroup",
    "Queued",
    "ReentrantCallbackGroup",
    "held_groups",
    "held_here",
    "holding",
]
