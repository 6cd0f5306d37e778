"""Managed entities (rclpy.lifecycle): what a lifecycle node's transitions switch on and off.

``TransitionCallbackReturn`` is what a transition callback answers; ``ManagedEntity`` has one
callback per transition, each answering SUCCESS; ``SimpleManagedEntity`` is enabled by activate
and disabled by deactivate; ``LifecyclePublisher`` is a publisher that is such an entity: while
it is not activated, ``publish`` drops the message without a word, as rclpy's does.
"""

from __future__ import annotations

import enum
import functools
from typing import TYPE_CHECKING, Any, NamedTuple, TypeVar

from rosl.node.lifecycle_machine import ERROR_LABEL, FAILURE_LABEL, SUCCESS_LABEL
from rosl.node.publisher import Publisher

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.idl.messages import Message

_F = TypeVar("_F", bound="Callable[..., None]")


class TransitionCallbackReturn(enum.Enum):
    """What a transition callback answers (lifecycle_msgs' TRANSITION_CALLBACK_* ids)."""

    SUCCESS = 97
    FAILURE = 98
    ERROR = 99

    def to_label(self) -> str:
        """The label of the transition this outcome takes (``transition_success``...)."""
        return {97: SUCCESS_LABEL, 98: FAILURE_LABEL, 99: ERROR_LABEL}[self.value]


class LifecycleState(NamedTuple):
    """The state a transition started from, as callbacks get it (rclpy's LifecycleState)."""

    label: str
    state_id: int


class ManagedEntity:
    """An entity whose transition callbacks a lifecycle node calls (each answers SUCCESS)."""

    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle configure."""
        return TransitionCallbackReturn.SUCCESS

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle cleanup."""
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle shutdown."""
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle activate."""
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle deactivate."""
        return TransitionCallbackReturn.SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Handle an error in another transition."""
        return TransitionCallbackReturn.SUCCESS


class SimpleManagedEntity(ManagedEntity):
    """A managed entity that is enabled while its node is active."""

    def __init__(self) -> None:
        self._enabled = False

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Enable."""
        self._enabled = True
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Disable."""
        self._enabled = False
        return TransitionCallbackReturn.SUCCESS

    @property
    def is_activated(self) -> bool:
        """Whether the entity is enabled."""
        return self._enabled

    @staticmethod
    def when_enabled(
        wrapped: Callable[..., None] | None = None,
        *,
        when_not_enabled: Callable[[], None] | None = None,
    ) -> Any:
        """Decorate a method so that it runs only while enabled (else ``when_not_enabled()``)."""

        def decorator(method: _F) -> _F:
            @functools.wraps(method)
            def only_when_enabled(self: SimpleManagedEntity, *args: Any, **kwargs: Any) -> None:
                if not self._enabled:
                    if when_not_enabled is not None:
                        when_not_enabled()
                    return
                method(self, *args, **kwargs)

            return only_when_enabled  # type: ignore[return-value]

        return decorator if wrapped is None else decorator(wrapped)


class LifecyclePublisher(SimpleManagedEntity, Publisher):
    """A publisher that sends only while its lifecycle node is active."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        SimpleManagedEntity.__init__(self)
        Publisher.__init__(self, *args, **kwargs)

    def publish(self, msg: Message | bytes | bytearray | memoryview) -> None:
        """Send ``msg`` if activated; drop it otherwise (rclpy drops it silently)."""
        if self._enabled:
            Publisher.publish(self, msg)
