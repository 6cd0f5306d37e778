"""Guard conditions: a callback an executor runs when another thread calls ``trigger()``."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.node.callback_groups import Executable

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.callback_groups import CallbackGroup
    from rosl.node.context import Context


class GuardCondition(Executable):
    """rclpy.guard_condition.GuardCondition: ``trigger()`` makes its executor run ``callback``.

    Triggers that come before the executor took the last one are merged into one call.
    """

    _what = "guard condition"

    def __init__(
        self,
        callback: Callable[[], Any] | None,
        callback_group: CallbackGroup | None,
        context: Context | None = None,
    ) -> None:
        from rosl.node.context import default_context

        self.callback = callback
        self._join(callback_group)
        self._context = context or default_context
        self._triggered = False
        self.destroyed = False

    def trigger(self) -> None:
        """Ask the executor to run the callback (from any thread)."""
        self._triggered = True
        self._context.wake_executors()

    def _ready(self) -> bool:
        return self._triggered and not self.destroyed

    def _take(self) -> Callable[[], Any] | None:
        self._triggered = False
        return self.callback

    def destroy(self) -> None:
        """Never run again."""
        self.destroyed = True
