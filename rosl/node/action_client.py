"""Action clients (rclpy.action.ActionClient) built from the node's clients and subscriptions.

Goals go out on ``<action>/_action/send_goal``, results and cancels on ``get_result`` and
``cancel_goal``; feedback (``<action>/_action/feedback``) reaches the callback given with the
goal, and the status array (``<action>/_action/status``) keeps each goal handle's ``status``
current. A goal's feedback received before its result is handed to the feedback callback
before the result future completes (the executor would otherwise take the result first).
The blocking calls (``send_goal``, ``get_result``, ``cancel_goal``) work inside callbacks
too, as :meth:`rosl.node.client.Client.call` does.
"""

from __future__ import annotations

import threading
import weakref
from typing import TYPE_CHECKING, Any

from rosl.idl.registry import get_message_class
from rosl.node import action_goals as goals
from rosl.node.qos import QoSProfile, qos_profile_action_status_default
from rosl.node.task import Future

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.idl.base import ActionType
    from rosl.node.callback_groups import CallbackGroup
    from rosl.node.node import Node

FEEDBACK_WAIT = 10.0  # seconds a result waits for a feedback callback running elsewhere


class ClientGoalHandle:
    """A goal sent by an :class:`ActionClient` (rclpy.action.client.ClientGoalHandle)."""

    def __init__(self, action_client: ActionClient, goal_id: Any, goal_response: Any) -> None:
        self._action_client = action_client
        self._goal_id = goal_id
        self._goal_response = goal_response
        self._status = goals.STATUS_UNKNOWN

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ClientGoalHandle) and self.goal_id == other.goal_id

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return (
            f"ClientGoalHandle <id: {self.goal_id.uuid}, accepted: {self.accepted}, "
            f"status: {self.status}>"
        )

    @property
    def goal_id(self) -> Any:
        """The goal's unique_identifier_msgs/UUID."""
        return self._goal_id

    @property
    def stamp(self) -> Any:
        """When the server accepted (or rejected) the goal."""
        return self._goal_response.stamp

    @property
    def accepted(self) -> bool:
        """Whether the server accepted the goal."""
        return bool(self._goal_response.accepted)

    @property
    def status(self) -> int:
        """The goal's last known action_msgs/GoalStatus value."""
        return self._status

    def _check_accepted(self, what: str) -> None:
        if not self.accepted:
            raise TypeError(f"Cannot {what}. Goal was rejected.")

    def cancel_goal(self) -> Any:
        """Ask the server to cancel the goal and wait for its CancelGoal response."""
        self._check_accepted("cancel goal")
        return self._action_client._cancel_client.call(self._action_client._cancel_request(self))

    def cancel_goal_async(self) -> Future[Any]:
        """Ask the server to cancel the goal; the future holds the CancelGoal response."""
        self._check_accepted("cancel goal")
        return self._action_client._cancel_goal_async(self)

    def get_result(self) -> Any:
        """Wait for the goal's GetResult response (``status`` and ``result``)."""
        self._check_accepted("get result")
        return self._action_client._get_result(self)

    def get_result_async(self) -> Future[Any]:
        """The goal's GetResult response (``status`` and ``result``), when the goal ends."""
        self._check_accepted("get result")
        return self._action_client._get_result_async(self)


class ActionClient:
    """Sends goals to one action (rclpy.action.ActionClient)."""

    def __init__(
        self,
        node: Node,
        action_type: type[ActionType],
        action_name: str,
        *,
        callback_group: CallbackGroup | None = None,
        goal_service_qos_profile: QoSProfile | None = None,
        result_service_qos_profile: QoSProfile | None = None,
        cancel_service_qos_profile: QoSProfile | None = None,
        feedback_sub_qos_profile: QoSProfile | None = None,
        status_sub_qos_profile: QoSProfile = qos_profile_action_status_default,
    ) -> None:
        del goal_service_qos_profile, result_service_qos_profile, cancel_service_qos_profile
        self._node = node
        self._action_type = action_type
        self.callback_group = callback_group or node.default_callback_group
        self.action_name = node.resolve_topic_name(action_name)
        base = self.action_name.rstrip("/") + "/_action/"
        impl = action_type.Impl
        group = self.callback_group
        self._goal_client = node.create_client(
            impl.SendGoalService, base + "send_goal", callback_group=group
        )
        self._cancel_client = node.create_client(
            impl.CancelGoalService, base + "cancel_goal", callback_group=group
        )
        self._result_client = node.create_client(
            impl.GetResultService, base + "get_result", callback_group=group
        )
        self._feedback_sub = node.create_subscription(
            impl.FeedbackMessage, base + "feedback", self._on_feedback,
            feedback_sub_qos_profile or QoSProfile(depth=10), callback_group=group,
        )  # fmt: skip
        self._status_sub = node.create_subscription(
            impl.GoalStatusMessage, base + "status", self._on_status, status_sub_qos_profile,
            callback_group=group,
        )  # fmt: skip
        self._lock = threading.Lock()
        self._feedback_callbacks: dict[bytes, Callable[[Any], Any]] = {}
        self._goal_handles: dict[bytes, weakref.ref[ClientGoalHandle]] = {}
        self._early: dict[bytes, list[Any]] = {}  # feedback that came before the goal response

    @property
    def action_type(self) -> type[ActionType]:
        """The action's class."""
        return self._action_type

    # --- the server --------------------------------------------------------------------------

    def server_is_ready(self) -> bool:
        """Whether a server of this action is in the graph (all three of its services)."""
        graph = self._node.participant.graph
        clients = (self._goal_client, self._cancel_client, self._result_client)
        return all(graph.has_server(c.srv_name) for c in clients)

    def wait_for_server(self, timeout_sec: float | None = None) -> bool:
        """Block until a server exists (None: no limit, as in rclpy); return whether it does."""
        graph = self._node.participant.graph
        return graph.wait_for(self.server_is_ready, timeout_sec)

    # --- goals -------------------------------------------------------------------------------

    def _request(self, goal: Any, goal_uuid: Any) -> Any:
        if not isinstance(goal, self._action_type.Goal):
            raise TypeError(
                f"goal must be a {self._action_type.Goal.__msgtype__}, got {type(goal).__name__}"
            )
        uuid_type = get_message_class("unique_identifier_msgs/msg/UUID")
        goal_id = goal_uuid if goal_uuid is not None else uuid_type(uuid=goals.new_uuid())
        return self._action_type.Impl.SendGoalService.Request(goal_id=goal_id, goal=goal)

    def send_goal_async(
        self,
        goal: Any,
        feedback_callback: Callable[[Any], Any] | None = None,
        goal_uuid: Any = None,
    ) -> Future[ClientGoalHandle]:
        """Send a goal; the future holds its :class:`ClientGoalHandle` once the server answers.

        ``feedback_callback(feedback_message)`` gets each FeedbackMessage for this goal.

        Raises:
            TypeError: ``goal`` is not the action's Goal message.
        """
        request = self._request(goal, goal_uuid)
        key = bytes(request.goal_id.uuid)
        with self._lock:
            if feedback_callback is not None:
                self._feedback_callbacks[key] = feedback_callback
            self._early[key] = []
        future: Future[ClientGoalHandle] = Future()
        sent = self._goal_client.call_async(request)

        def answered(call: Future[Any]) -> None:
            error = call.exception()
            if error is not None:
                with self._lock:
                    self._early.pop(key, None)
                future.set_exception(error)
                return
            future.set_result(self._handle(request.goal_id, call.result()))
            with self._lock:  # as rclpy: the goal response first, then its feedback
                early = self._early.pop(key, [])
            for message in early:
                self._on_feedback(message)

        sent.add_done_callback(answered)
        return future

    def send_goal(self, goal: Any, **kwargs: Any) -> Any:
        """Send a goal and wait for its GetResult response (None when it is rejected)."""
        feedback_callback = kwargs.get("feedback_callback")
        request = self._request(goal, kwargs.get("goal_uuid"))
        if feedback_callback is not None:
            with self._lock:
                self._feedback_callbacks[bytes(request.goal_id.uuid)] = feedback_callback
        handle = self._handle(request.goal_id, self._goal_client.call(request))
        return self._get_result(handle) if handle.accepted else None

    def _handle(self, goal_id: Any, response: Any) -> ClientGoalHandle:
        handle = ClientGoalHandle(self, goal_id, response)
        key = bytes(goal_id.uuid)
        with self._lock:
            if handle.accepted:
                handle._status = goals.STATUS_ACCEPTED
                self._goal_handles[key] = weakref.ref(handle)
            else:
                self._feedback_callbacks.pop(key, None)
        return handle

    def _get_result_async(self, handle: ClientGoalHandle) -> Future[Any]:
        request = self._action_type.Impl.GetResultService.Request(goal_id=handle.goal_id)
        future = self._result_client.call_async(request)
        future.add_done_callback(lambda done: self._ended(handle, done))
        return future

    def _get_result(self, handle: ClientGoalHandle) -> Any:
        request = self._action_type.Impl.GetResultService.Request(goal_id=handle.goal_id)
        future: Future[Any] = Future()
        future.set_result(self._result_client.call(request))
        self._ended(handle, future)
        return future.result()

    def _ended(self, handle: ClientGoalHandle, done: Future[Any]) -> None:
        self._drain_feedback()
        key = bytes(handle.goal_id.uuid)
        with self._lock:
            self._feedback_callbacks.pop(key, None)
            self._goal_handles.pop(key, None)
        response = None if done.exception() is not None else done.result()
        if response is not None:
            handle._status = int(response.status)

    def _drain_feedback(self) -> None:
        """Run the feedback already received before a result: the server sent it earlier.

        Waits (bounded) for a feedback callback running on another thread: the goal's feedback
        callback is forgotten after this.
        """
        self._feedback_sub.drain(wait=FEEDBACK_WAIT)

    def _cancel_request(self, handle: ClientGoalHandle) -> Any:
        info = get_message_class("action_msgs/msg/GoalInfo")(goal_id=handle.goal_id)
        return self._action_type.Impl.CancelGoalService.Request(goal_info=info)

    def _cancel_goal_async(self, handle: ClientGoalHandle) -> Future[Any]:
        return self._cancel_client.call_async(self._cancel_request(handle))

    # --- topics ------------------------------------------------------------------------------

    def _on_feedback(self, message: Any) -> Any:
        key = bytes(message.goal_id.uuid)
        with self._lock:
            if key in self._early:
                self._early[key].append(message)
                return None
            callback = self._feedback_callbacks.get(key)
        return None if callback is None else callback(message)

    def _on_status(self, message: Any) -> None:
        for status in message.status_list:
            key = bytes(status.goal_info.goal_id.uuid)
            with self._lock:
                ref = self._goal_handles.get(key)
                handle = None if ref is None else ref()
                if handle is None:
                    continue
                handle._status = int(status.status)
                if status.status in goals.TERMINAL:
                    self._goal_handles.pop(key, None)

    def destroy(self) -> None:
        """Stop using the action."""
        for client in (self._goal_client, self._cancel_client, self._result_client):
            self._node.destroy_client(client)
        for subscription in (self._feedback_sub, self._status_sub):
            self._node.destroy_subscription(subscription)
