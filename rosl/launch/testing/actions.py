"""launch_testing.actions: ``ReadyToTest``, the action that starts the active tests."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.launch.description import Action

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from rosl.launch.context import LaunchContext


class ReadyToTest(Action):
    """Signal that the processes under test are up: the active tests start when it runs.

    Put it in the launch description where the system is ready: beside the processes (at
    once), in a ``TimerAction`` (after a delay) or in an ``OnProcessStart`` handler.
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self._callbacks: list[Callable[[], None]] = []

    def _add_callback(self, callback: Callable[[], None]) -> None:
        self._callbacks.append(callback)

    def execute(self, context: LaunchContext) -> None:
        """Tell the test runner."""
        for callback in self._callbacks:
            callback()


def ready_actions(entities: list[Any]) -> Iterator[ReadyToTest]:
    """Every ReadyToTest among ``entities`` and their sub-entities, depth first."""
    for entity in entities:
        if isinstance(entity, ReadyToTest):
            yield entity
        children = getattr(entity, "children", None)
        if callable(children):
            yield from ready_actions(list(children()))


__all__ = ["ReadyToTest"]
