"""launch_ros's lifecycle events: ChangeState, StateTransition and OnStateTransition.

``EmitEvent(event=ChangeState(lifecycle_node_matcher=..., transition_id=...))`` asks every
LifecycleNode action the matcher accepts to take a transition (over its ``change_state``
service). Each state change a launched lifecycle node publishes on ``transition_event`` becomes
a ``StateTransition`` event, which ``OnStateTransition`` handlers match by node, transition,
start state and goal state (labels).
"""

from __future__ import annotations

import collections
from typing import TYPE_CHECKING, Any, ClassVar

from rosl.launch.description import Action
from rosl.launch.errors import LaunchError
from rosl.launch.event_handlers import EventHandler, _as_list
from rosl.node.lifecycle_machine import STATES

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.launch.context import LaunchContext


_TRANSITION_WORDS = (
    "CREATE", "CONFIGURE", "CLEANUP", "ACTIVATE", "DEACTIVATE", "UNCONFIGURED_SHUTDOWN",
    "INACTIVE_SHUTDOWN", "ACTIVE_SHUTDOWN", "DESTROY",
)  # fmt: skip


def matches_node_name(node_name: str) -> Callable[[Any], bool]:
    """A matcher accepting the lifecycle node of that full name (``/ns/name``)."""
    return lambda action: getattr(action, "lifecycle_node_name", None) == node_name


class ChangeState(Action):
    """Ask lifecycle nodes to take a transition (launch_ros.events.lifecycle.ChangeState)."""

    name = "launch_ros.events.lifecycle.ChangeState"
    valid_transitions: ClassVar[collections.OrderedDict[int, str]] = collections.OrderedDict(
        (i, f"TRANSITION_{word}") for i, word in enumerate(_TRANSITION_WORDS)
    )
    valid_states: ClassVar[collections.OrderedDict[int, str]] = collections.OrderedDict(
        (s.id, f"{'PRIMARY' if s.id < 10 else 'TRANSITION'}_STATE_{s.label.upper()}")
        for s in STATES
    )

    def __init__(
        self, *, lifecycle_node_matcher: Callable[[Any], bool], transition_id: int, **kwargs: Any
    ) -> None:
        super().__init__(**kwargs)
        if transition_id not in self.valid_transitions:
            from rosl.launch.ros_actions import _user_site

            expected = ", ".join(f"{v}: {k}" for k, v in self.valid_transitions.items())
            raise LaunchError(
                f"{_user_site()}ChangeState: given transition_id of '{transition_id}', "
                f"expected one of {{{expected}}}"
            )
        self.lifecycle_node_matcher = lifecycle_node_matcher
        self.transition_id = transition_id

    def execute(self, context: LaunchContext) -> None:
        """Send the request to each matching lifecycle node the launch started."""
        from rosl.launch.lifecycle import LifecycleManager

        manager = LifecycleManager.find(context)
        if manager is None:
            return
        for action in manager.actions():
            if self.lifecycle_node_matcher(action):
                manager.change_state(action, self.transition_id)


class StateTransition:
    """A launched lifecycle node changed state (launch_ros.events.lifecycle.StateTransition)."""

    name = "launch_ros.events.lifecycle.StateTransition"
    kind = "state_transition"

    def __init__(self, *, action: Any, msg: Any) -> None:
        self.action = action
        self.msg = msg
        self.timestamp: int = msg.timestamp
        self.transition: str = msg.transition.label
        self.start_state: str = msg.start_state.label
        self.goal_state: str = msg.goal_state.label


class OnStateTransition(EventHandler):
    """React to a lifecycle node's state change (launch_ros.event_handlers.OnStateTransition).

    Each of ``target_lifecycle_node``, ``transition``, ``start_state`` and ``goal_state`` that
    is given must match; a ``matcher`` (a callable taking the event) replaces them all.
    """

    kinds = ("state_transition",)

    def __init__(
        self,
        *,
        entities: Any,
        target_lifecycle_node: Any = None,
        transition: str | None = None,
        start_state: str | None = None,
        goal_state: str | None = None,
        matcher: Callable[[Any], bool] | None = None,
        handle_once: bool = False,
    ) -> None:
        super().__init__(target_action=target_lifecycle_node, handle_once=handle_once)
        if target_lifecycle_node is not None and not getattr(
            target_lifecycle_node, "is_lifecycle_node", False
        ):
            raise LaunchError(
                'OnStateTransition requires a "LifecycleNode" action as the target, '
                f"target_lifecycle_node is a {type(target_lifecycle_node).__name__}"
            )
        self.reaction = entities
        self.wanted = {"transition": transition, "start_state": start_state,
                       "goal_state": goal_state}  # fmt: skip
        self.matcher = matcher

    def matches(self, event: Any) -> bool:
        """Whether this handler reacts to ``event``."""
        if event.kind not in self.kinds or (self.handle_once and self.handled):
            return False
        if self.matcher is not None:
            return bool(self.matcher(event))
        if self.target_action is not None and event.action is not self.target_action:
            return False
        return all(v is None or getattr(event, k) == v for k, v in self.wanted.items())

    def entities(self, event: Any, context: LaunchContext) -> list[Any]:
        """The entities to run."""
        self.handled = True
        return _as_list(self.reaction)
