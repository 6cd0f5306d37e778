"""The server's handle of one accepted goal (rclpy.action.server.ServerGoalHandle).

The handle moves its goal through action_msgs/GoalStatus's states (see
:mod:`rosl.node.action_goals`), publishes feedback for it, and holds the future its result
goes into; every state change makes the server publish its status array.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from rosl.node import action_goals as goals
from rosl.node.action_goals import GoalEvent
from rosl.node.task import Future

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.action_server import ActionServer


class ServerGoalHandle:
    """One accepted goal on the server (rclpy.action.server.ServerGoalHandle)."""

    def __init__(self, server: ActionServer, goal_info: Any, goal_request: Any) -> None:
        self._server = server
        self._goal_info = goal_info
        self._goal_request = goal_request
        self._status = goals.STATUS_ACCEPTED
        self._ended_ns: int | None = None
        self._result_future: Future[Any] = Future()
        self._lock = threading.Lock()
        self._destroyed = False

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ServerGoalHandle) and self.goal_id == other.goal_id

    __hash__ = None  # type: ignore[assignment]

    @property
    def request(self) -> Any:
        """The goal message the client sent."""
        return self._goal_request

    @property
    def goal_id(self) -> Any:
        """The goal's unique_identifier_msgs/UUID."""
        return self._goal_info.goal_id

    @property
    def status(self) -> int:
        """The goal's action_msgs/GoalStatus value."""
        return goals.STATUS_UNKNOWN if self._destroyed else self._status

    @property
    def is_active(self) -> bool:
        """Whether the goal has not ended yet."""
        return self.status in goals.ACTIVE

    @property
    def is_cancel_requested(self) -> bool:
        """Whether a client asked to cancel it (and the cancel callback agreed)."""
        return self.status == goals.STATUS_CANCELING

    def _update_state(self, event: GoalEvent) -> None:
        with self._lock:
            if self._destroyed:
                return
            self._status = goals.next_status(self._status, event)
            if self._status in goals.TERMINAL:
                self._ended_ns = self._server._now_ns()
        self._server._publish_status()

    def execute(self, execute_callback: Callable[[Any], Any] | None = None) -> None:
        """Start executing: the execute callback (this one, or the server's) runs as a task."""
        if not self.is_cancel_requested:
            self._update_state(GoalEvent.EXECUTE)
        self._server._notify_execute(self, execute_callback)

    def publish_feedback(self, feedback: Any) -> None:
        """Send feedback for this goal to the clients.

        Raises:
            TypeError: ``feedback`` is not the action's Feedback message.
        """
        action = self._server.action_type
        if not isinstance(feedback, action.Feedback):
            raise TypeError(
                f"publish_feedback takes a {action.Feedback.__msgtype__}, "
                f"got {type(feedback).__name__}"
            )
        if self._destroyed:
            return
        message = action.Impl.FeedbackMessage(goal_id=self.goal_id, feedback=feedback)
        self._server._feedback.publish(message)

    def succeed(self) -> None:
        """The goal ended well."""
        self._update_state(GoalEvent.SUCCEED)

    def abort(self) -> None:
        """The goal failed."""
        self._update_state(GoalEvent.ABORT)

    def canceled(self) -> None:
        """The goal stopped after a cancel request."""
        self._update_state(GoalEvent.CANCELED)

    def destroy(self) -> None:
        """Forget the goal."""
        self._destroyed = True
