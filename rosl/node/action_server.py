"""Action servers (rclpy.action.ActionServer) built from the node's services and publishers.

An action ``/fibonacci`` is three services, ``/fibonacci/_action/send_goal``, ``cancel_goal``
and ``get_result``, and two topics, ``/fibonacci/_action/feedback`` and ``/fibonacci/_action/
status`` (transient local: a late client gets the last status array), as in ROS 2. The
services answer when their work is done, not when the callback returns: a result request is
answered when the goal ends, without holding the server's callback group meanwhile. Accepted
goals run their execute callback as an executor task; a goal's result is kept
``result_timeout`` seconds after it ends.
"""

from __future__ import annotations

import inspect
import threading
from typing import TYPE_CHECKING, Any

from rosl.idl.registry import get_message_class
from rosl.node import action_goals as goals
from rosl.node.action_goals import CancelResponse, GoalEvent, GoalResponse, await_or_execute
from rosl.node.clock import NS
from rosl.node.qos import QoSProfile, qos_profile_action_status_default
from rosl.node.server_goal_handle import ServerGoalHandle
from rosl.node.service import Service

if TYPE_CHECKING:
    from collections.abc import Callable, Coroutine

    from rosl.idl.base import ActionType, ServiceType
    from rosl.node.callback_groups import CallbackGroup
    from rosl.node.node import Node
    from rosl.node.publisher import Publisher
    from rosl.node.timer import Timer


class ActionService(Service):
    """A service whose handler answers through ``reply(response)``, now or later.

    A handler that raises before it replied answers the caller with the failure at once (as
    a plain service does), so a client is never left waiting for a goal response.
    """

    def _answer(self, request: Any, address: tuple[int, int, int]) -> Any:
        replied: list[bool] = []

        def reply(response: Any) -> None:
            replied.append(True)
            self._respond(response, address)

        try:
            result = self.callback(request, reply)
        except Exception as err:
            if not replied:
                self._fail(err, address)
            raise
        if inspect.iscoroutine(result):
            return self._guarded(result, address, replied)
        return None

    async def _guarded(
        self, pending: Coroutine[Any, Any, Any], address: tuple[int, int, int], replied: list[bool]
    ) -> Any:
        try:
            return await pending
        except Exception as err:
            if not replied:
                self._fail(err, address)
            raise


def default_goal_callback(goal_request: Any) -> GoalResponse:
    """Accept every goal."""
    return GoalResponse.ACCEPT


def default_handle_accepted_callback(goal_handle: ServerGoalHandle) -> None:
    """Execute an accepted goal at once."""
    goal_handle.execute()


def default_cancel_callback(cancel_request: Any) -> CancelResponse:
    """Refuse every cancel request."""
    return CancelResponse.REJECT


class ActionServer:
    """Serves one action (rclpy.action.ActionServer)."""

    def __init__(
        self,
        node: Node,
        action_type: type[ActionType],
        action_name: str,
        execute_callback: Callable[[ServerGoalHandle], Any],
        *,
        callback_group: CallbackGroup | None = None,
        goal_callback: Callable[[Any], Any] = default_goal_callback,
        handle_accepted_callback: Callable[[ServerGoalHandle], Any] = (
            default_handle_accepted_callback
        ),
        cancel_callback: Callable[[ServerGoalHandle], Any] = default_cancel_callback,
        goal_service_qos_profile: QoSProfile | None = None,
        result_service_qos_profile: QoSProfile | None = None,
        cancel_service_qos_profile: QoSProfile | None = None,
        feedback_pub_qos_profile: QoSProfile | None = None,
        status_pub_qos_profile: QoSProfile = qos_profile_action_status_default,
        result_timeout: float = 900,
    ) -> None:
        del goal_service_qos_profile, result_service_qos_profile, cancel_service_qos_profile
        self._node = node
        self._action_type = action_type
        self._lock = threading.RLock()
        self._goal_handles: dict[bytes, ServerGoalHandle] = {}
        self.register_execute_callback(execute_callback)
        self.register_goal_callback(goal_callback)
        self.register_handle_accepted_callback(handle_accepted_callback)
        self.register_cancel_callback(cancel_callback)
        self.callback_group = callback_group or node.default_callback_group
        self._result_timeout_ns = max(0, int(result_timeout * NS))
        self.action_name = node.resolve_topic_name(action_name)
        base = self.action_name.rstrip("/") + "/_action/"
        impl = action_type.Impl
        self._services = [
            self._service(impl.SendGoalService, base + "send_goal", self._on_goal),
            self._service(impl.CancelGoalService, base + "cancel_goal", self._on_cancel),
            self._service(impl.GetResultService, base + "get_result", self._on_result),
        ]
        self._feedback: Publisher = node.create_publisher(
            impl.FeedbackMessage,
            base + "feedback",
            feedback_pub_qos_profile or QoSProfile(depth=10),
        )
        self._status: Publisher = node.create_publisher(
            impl.GoalStatusMessage, base + "status", status_pub_qos_profile
        )
        period = min(max(result_timeout / 2, 0.01), 1.0)
        self._expiry: Timer | None = node.create_timer(period, self._expire_goals)
        self._expiry._internal = True

    def _service(
        self, srv_type: type[ServiceType], name: str, handler: Callable[..., Any]
    ) -> ActionService:
        service = ActionService(self._node, srv_type, name, handler)
        self._node._join(service, self.callback_group)
        self._node.services.append(service)
        self._node.participant.discovery.changed()
        return service

    @property
    def action_type(self) -> type[ActionType]:
        """The action's class."""
        return self._action_type

    def _now_ns(self) -> int:
        return self._node.get_clock().now().nanoseconds

    # --- requests ----------------------------------------------------------------------------

    async def _on_goal(self, request: Any, reply: Callable[[Any], None]) -> None:
        key = bytes(request.goal_id.uuid)
        accepted = False
        if key in self._goal_handles:
            self._node.get_logger().warn(f"goal id {key.hex()} is already in use; rejected")
        else:
            answer = await await_or_execute(self._goal_callback, request.goal)
            if not isinstance(answer, GoalResponse):
                self._node.get_logger().warn(
                    "Goal request callback did not return a GoalResponse type. Rejecting goal."
                )
            accepted = answer is GoalResponse.ACCEPT
        stamp = self._node.get_clock().now().to_msg()
        handle = None
        if accepted:
            info = get_message_class("action_msgs/msg/GoalInfo")(
                goal_id=request.goal_id, stamp=stamp
            )
            handle = ServerGoalHandle(self, info, request.goal)
            with self._lock:
                self._goal_handles[key] = handle
        reply(self._action_type.Impl.SendGoalService.Response(accepted=accepted, stamp=stamp))
        if handle is not None:
            await await_or_execute(self._handle_accepted_callback, handle)

    async def _on_cancel(self, request: Any, reply: Callable[[Any], None]) -> None:
        cancel = self._action_type.Impl.CancelGoalService.Response
        candidates, code = self._cancel_candidates(request.goal_info)
        canceling = []
        for handle in candidates:
            answer = await await_or_execute(self._cancel_callback, handle)
            if answer is CancelResponse.ACCEPT and handle.status in goals.CANCELABLE:
                handle._update_state(GoalEvent.CANCEL_GOAL)
                canceling.append(handle._goal_info)
        if code == cancel.ERROR_NONE and not canceling:
            code = cancel.ERROR_REJECTED
        reply(cancel(return_code=code, goals_canceling=canceling))

    def _cancel_candidates(self, info: Any) -> tuple[list[ServerGoalHandle], int]:
        """The goals a cancel request names, and rcl_action's return code so far."""
        cancel = self._action_type.Impl.CancelGoalService.Response
        wanted = bytes(info.goal_id.uuid)
        before_ns = info.stamp.sec * NS + info.stamp.nanosec
        with self._lock:
            handles = list(self._goal_handles.items())
        if any(wanted) and before_ns == 0:
            for key, handle in handles:
                if key == wanted:
                    if handle.status in goals.CANCELABLE:
                        return [handle], cancel.ERROR_NONE
                    return [], cancel.ERROR_GOAL_TERMINATED
            return [], cancel.ERROR_UNKNOWN_GOAL_ID
        if not any(wanted) and before_ns == 0:
            before_ns = 2**63 - 1
        found = []
        for key, handle in handles:
            stamp = handle._goal_info.stamp
            early = stamp.sec * NS + stamp.nanosec <= before_ns
            if (early or key == wanted) and handle.status in goals.CANCELABLE:
                found.append(handle)
        return found, cancel.ERROR_NONE

    def _on_result(self, request: Any, reply: Callable[[Any], None]) -> None:
        with self._lock:
            handle = self._goal_handles.get(bytes(request.goal_id.uuid))
        if handle is None:
            response = self._action_type.Impl.GetResultService.Response()
            response.status = goals.STATUS_UNKNOWN
            reply(response)
            return
        handle._result_future.add_done_callback(lambda done: reply(done.result()))

    # --- goals -------------------------------------------------------------------------------

    def _notify_execute(
        self, handle: ServerGoalHandle, execute_callback: Callable[[Any], Any] | None
    ) -> None:
        callback = execute_callback or self._execute_callback
        executor = self._node.executor
        if executor is None:
            from rosl.runtime import get_global_executor

            executor = get_global_executor()
        executor.create_task(self._execute_goal, callback, handle)

    async def _execute_goal(self, callback: Callable[[Any], Any], handle: ServerGoalHandle) -> None:
        result_type = self._action_type.Result
        try:
            result = await await_or_execute(callback, handle)
        except Exception as err:
            self._node._callback_failed(err, f"action {self.action_name} (execute)")
            result = None
        if handle.is_active:
            self._node.get_logger().warn(
                f"Goal state not set, assuming aborted. Goal ID: {bytes(handle.goal_id.uuid).hex()}"
            )
            handle.abort()
        if not isinstance(result, result_type):
            if result is not None:
                self._node.get_logger().error(
                    f"execute callback of {self.action_name} returned {type(result).__name__}, "
                    f"not a {result_type.__msgtype__}; sending an empty result"
                )
            result = result_type()
        response = self._action_type.Impl.GetResultService.Response(
            status=handle.status, result=result
        )
        handle._result_future.set_result(response)

    def _publish_status(self) -> None:
        status_type = get_message_class("action_msgs/msg/GoalStatus")
        with self._lock:
            handles = list(self._goal_handles.values())
        message = self._action_type.Impl.GoalStatusMessage(
            status_list=[status_type(goal_info=h._goal_info, status=h.status) for h in handles]
        )
        self._status.publish(message)

    def _expire_goals(self) -> None:
        now = self._now_ns()
        with self._lock:
            expired = [
                key
                for key, handle in self._goal_handles.items()
                if handle._ended_ns is not None
                and handle._result_future.done()
                and now - handle._ended_ns > self._result_timeout_ns
            ]
            for key in expired:
                self._goal_handles.pop(key).destroy()
        if expired:
            self._publish_status()

    # --- callbacks -----------------------------------------------------------------------------

    def register_execute_callback(self, execute_callback: Callable[[Any], Any]) -> None:
        """Set the callback that executes goals.

        Raises:
            TypeError: it is not callable.
        """
        if not callable(execute_callback):
            raise TypeError("Failed to register goal execution callback: not callable")
        self._execute_callback = execute_callback

    def register_goal_callback(self, goal_callback: Callable[[Any], Any] | None) -> None:
        """Set the callback deciding whether to accept a goal (None: accept all)."""
        self._goal_callback = goal_callback or default_goal_callback

    def register_handle_accepted_callback(
        self, handle_accepted_callback: Callable[[ServerGoalHandle], Any] | None
    ) -> None:
        """Set the callback given each accepted goal (None: execute it at once)."""
        self._handle_accepted_callback = (
            handle_accepted_callback or default_handle_accepted_callback
        )

    def register_cancel_callback(self, cancel_callback: Callable[[Any], Any] | None) -> None:
        """Set the callback deciding whether to cancel a goal (None: refuse all)."""
        self._cancel_callback = cancel_callback or default_cancel_callback

    def destroy(self) -> None:
        """Stop serving the action."""
        for service in self._services:
            self._node.destroy_service(service)
        self._services = []
        self._node.destroy_publisher(self._feedback)
        self._node.destroy_publisher(self._status)
        if self._expiry is not None:
            self._node.destroy_timer(self._expiry)
            self._expiry = None
        with self._lock:
            for handle in self._goal_handles.values():
                handle.destroy()
