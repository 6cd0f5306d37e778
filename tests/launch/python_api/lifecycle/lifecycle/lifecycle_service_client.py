"""Drives lc_talker through its states over its lifecycle services, then exits."""

import sys
import time

import rclpy
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
from rclpy.node import Node

TALKER = "lc_talker"
TIMEOUT = 10.0


class ServiceClient(Node):
    def __init__(self):
        super().__init__("lc_client")
        self.get_state_client = self.create_client(GetState, f"/{TALKER}/get_state")
        self.change_state_client = self.create_client(ChangeState, f"/{TALKER}/change_state")

    def call(self, client, request):
        if not client.wait_for_service(timeout_sec=TIMEOUT):
            raise RuntimeError(f"service {client.srv_name} is not available")
        future = client.call_async(request)
        rclpy.spin_until_future_complete(self, future, timeout_sec=TIMEOUT)
        if not future.done():
            raise RuntimeError(f"service {client.srv_name} did not answer")
        return future.result()

    def get_state(self):
        state = self.call(self.get_state_client, GetState.Request()).current_state
        self.get_logger().info(f"Node {TALKER} has current state {state.label}.")
        return state.label

    def change_state(self, transition_id):
        request = ChangeState.Request()
        request.transition.id = transition_id
        if not self.call(self.change_state_client, request).success:
            self.get_logger().warning(f"Failed to trigger transition {transition_id}")
            return False
        self.get_logger().info(f"Transition {transition_id} successfully triggered.")
        return True

    def wait_for_listener(self):
        deadline = time.monotonic() + TIMEOUT
        while self.count_subscribers("/lifecycle_chatter") == 0 and time.monotonic() < deadline:
            rclpy.spin_once(self, timeout_sec=0.1)

    def dwell(self, seconds):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            rclpy.spin_once(self, timeout_sec=0.1)


def main(args=None):
    rclpy.init(args=args)
    node = ServiceClient()
    node.wait_for_listener()
    script = [
        Transition.TRANSITION_CONFIGURE,
        Transition.TRANSITION_ACTIVATE,
        Transition.TRANSITION_DEACTIVATE,
        Transition.TRANSITION_ACTIVATE,
        Transition.TRANSITION_DEACTIVATE,
        Transition.TRANSITION_CLEANUP,
        Transition.TRANSITION_UNCONFIGURED_SHUTDOWN,
    ]
    ok = True
    node.get_state()
    for transition_id in script:
        ok = node.change_state(transition_id) and ok
        if node.get_state() == "active":
            node.dwell(1.0)
    node.destroy_node()
    rclpy.try_shutdown()
    sys.exit(0 if ok else 1)
