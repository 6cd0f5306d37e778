"""Prints what the managed talker publishes, and each of its state changes."""

import contextlib

import rclpy
from lifecycle_msgs.msg import TransitionEvent
from rclpy.node import Node
from std_msgs.msg import String


class LifecycleListener(Node):
    def __init__(self):
        super().__init__("listener")
        self.data = self.create_subscription(String, "lifecycle_chatter", self.on_data, 10)
        self.notifications = self.create_subscription(
            TransitionEvent, "/lc_talker/transition_event", self.on_notification, 10
        )

    def on_data(self, msg):
        self.get_logger().info(f"data_callback: {msg.data}")

    def on_notification(self, msg):
        self.get_logger().info(
            f"notify_callback: Transition from state {msg.start_state.label} "
            f"to {msg.goal_state.label}"
        )


def main(args=None):
    rclpy.init(args=args)
    node = LifecycleListener()
    with contextlib.suppress(KeyboardInterrupt):
        rclpy.spin(node)
    node.destroy_node()
    rclpy.try_shutdown()
