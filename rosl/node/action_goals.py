"""Action goals: the states a goal goes through, and the words for them (rcl_action's machine).

A goal is ACCEPTED, then EXECUTING; a cancel request moves an accepted or executing goal to
CANCELING; it ends SUCCEEDED, ABORTED or CANCELED. Values are action_msgs/GoalStatus's.
"""

from __future__ import annotations

import enum
import inspect
import uuid
from typing import TYPE_CHECKING, Any

from rosl.node.errors import NodeError

if TYPE_CHECKING:
    from collections.abc import Callable

STATUS_UNKNOWN = 0
STATUS_ACCEPTED = 1
STATUS_EXECUTING = 2
STATUS_CANCELING = 3
STATUS_SUCCEEDED = 4
STATUS_CANCELED = 5
STATUS_ABORTED = 6
ACTIVE = (STATUS_ACCEPTED, STATUS_EXECUTING, STATUS_CANCELING)
CANCELABLE = (STATUS_ACCEPTED, STATUS_EXECUTING)
TERMINAL = (STATUS_SUCCEEDED, STATUS_CANCELED, STATUS_ABORTED)
STATUS_WORDS = {
    STATUS_ACCEPTED: "ACCEPTED",
    STATUS_EXECUTING: "EXECUTING",
    STATUS_CANCELING: "CANCELING",
    STATUS_SUCCEEDED: "SUCCEEDED",
    STATUS_CANCELED: "CANCELED",
    STATUS_ABORTED: "ABORTED",
}


class GoalResponse(enum.Enum):
    """What a goal callback answers (rclpy.action.GoalResponse)."""

    REJECT = 1
    ACCEPT = 2


class CancelResponse(enum.Enum):
    """What a cancel callback answers (rclpy.action.CancelResponse)."""

    REJECT = 1
    ACCEPT = 2


class GoalEvent(enum.Enum):
    """What moves a goal from one state to the next."""

    EXECUTE = 1
    CANCEL_GOAL = 2
    SUCCEED = 3
    ABORT = 4
    CANCELED = 5


_TRANSITIONS: dict[tuple[int, GoalEvent], int] = {
    (STATUS_ACCEPTED, GoalEvent.EXECUTE): STATUS_EXECUTING,
    (STATUS_ACCEPTED, GoalEvent.CANCEL_GOAL): STATUS_CANCELING,
    (STATUS_EXECUTING, GoalEvent.CANCEL_GOAL): STATUS_CANCELING,
    (STATUS_EXECUTING, GoalEvent.SUCCEED): STATUS_SUCCEEDED,
    (STATUS_EXECUTING, GoalEvent.ABORT): STATUS_ABORTED,
    (STATUS_CANCELING, GoalEvent.CANCELED): STATUS_CANCELED,
    (STATUS_CANCELING, GoalEvent.SUCCEED): STATUS_SUCCEEDED,
    (STATUS_CANCELING, GoalEvent.ABORT): STATUS_ABORTED,
}


class GoalStateError(NodeError, RuntimeError):
    """A goal was asked to do what its state does not allow (e.g. succeed before executing)."""


def next_status(status: int, event: GoalEvent) -> int:
    """The status after ``event``.

    Raises:
        GoalStateError: the transition is not allowed.
    """
    after = _TRANSITIONS.get((status, event))
    if after is None:
        raise GoalStateError(
            f"goal cannot {event.name.lower()} while {STATUS_WORDS.get(status, 'UNKNOWN')}"
        )
    return after


def status_word(status: int) -> str:
    """``SUCCEEDED`` for 4 (ros2 action send_goal's words; UNKNOWN for anything else)."""
    return STATUS_WORDS.get(status, "UNKNOWN")


def new_uuid() -> bytes:
    """16 random bytes for a goal id."""
    return uuid.uuid4().bytes


async def await_or_execute(callback: Callable[..., Any], *args: Any) -> Any:
    """Run ``callback(*args)``; await its result when it is a coroutine (rclpy's helper)."""
    result = callback(*args)
    if inspect.isawaitable(result):
        return await result
    return result
