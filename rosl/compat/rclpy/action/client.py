"""rclpy.action.client."""

from rosl.node.action_client import ActionClient, ClientGoalHandle

__all__ = ["ActionClient", "ClientGoalHandle"]
