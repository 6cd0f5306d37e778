"""rclpy.action.server."""

from rosl.node.action_goals import CancelResponse, GoalEvent, GoalResponse
from rosl.node.action_server import (
    ActionServer,
    default_cancel_callback,
    default_goal_callback,
    default_handle_accepted_callback,
)
from rosl.node.server_goal_handle import ServerGoalHandle

__all__ = [
    "ActionServer",
    "CancelResponse",
    "GoalEvent",
    "GoalResponse",
    "ServerGoalHandle",
    "default_cancel_callback",
    "default_goal_callback",
    "default_handle_accepted_callback",
]
