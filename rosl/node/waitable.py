"""Waitables: entities that decide for themselves when they are ready (rclpy.waitable).

rclpy's waitables put rcl handles in the wait set; rosl has no such handles, so a waitable
here says ``is_ready`` from its own state and calls :meth:`Waitable.wake` when that changes
(from any thread). The executor then calls ``take_data()`` and ``execute(data)`` (a
coroutine, as in rclpy, or a plain function).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.node.callback_groups import Executable

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.callback_groups import CallbackGroup
    from rosl.node.context import Context


class NumberOfEntities:
    """rclpy's count of what a waitable adds to a wait set (kept for API compatibility)."""

    def __init__(
        self,
        num_subs: int = 0,
        num_gcs: int = 0,
        num_timers: int = 0,
        num_clients: int = 0,
        num_services: int = 0,
        num_events: int = 0,
    ) -> None:
        self.num_subscriptions = num_subs
        self.num_guard_conditions = num_gcs
        self.num_timers = num_timers
        self.num_clients = num_clients
        self.num_services = num_services
        self.num_events = num_events


class Waitable(Executable):
    """Subclass and implement ``is_ready``, ``take_data`` and ``execute``."""

    def __init__(
        self, callback_group: CallbackGroup | None, context: Context | None = None
    ) -> None:
        from rosl.node.context import default_context

        self._join(callback_group)
        self._context = context or default_context
        self._what = type(self).__name__

    def is_ready(self, wait_set: Any) -> bool:
        """Whether there is work (rosl passes no wait set)."""
        return False

    def take_data(self) -> Any:
        """Take the work; its result is passed to :meth:`execute`."""
        return None

    async def execute(self, taken_data: Any) -> None:
        """Do the work (may await futures)."""

    def add_to_wait_set(self, wait_set: Any) -> None:
        """Nothing to add: rosl asks :meth:`is_ready` directly."""

    def get_num_entities(self) -> NumberOfEntities:
        """No rcl entities."""
        return NumberOfEntities()

    def wake(self) -> None:
        """Tell the executor that :meth:`is_ready` may have changed."""
        self._context.wake_executors()

    def __enter__(self) -> None:
        return None

    def __exit__(self, *exc: object) -> None:
        return None

    def _ready(self) -> bool:
        return bool(self.is_ready(None))

    def _take(self) -> Callable[[], Any] | None:
        data = self.take_data()
        return lambda: self.execute(data)
