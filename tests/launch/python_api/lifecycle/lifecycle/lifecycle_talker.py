"""A managed talker: it publishes on lifecycle_chatter only while it is active."""

import contextlib

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.lifecycle import Node, State, TransitionCallbackReturn
from std_msgs.msg import String


class LifecycleTalker(Node):
    def __init__(self):
        self.count = 0
        self.publisher = None
        self.timer = None
        super().__init__("lc_talker")

    def tick(self):
        msg = String(data=f"Lifecycle HelloWorld #{self.count}")
        self.count += 1
        if self.publisher.is_activated:
            self.get_logger().info(f"Lifecycle publisher is active. Publishing: [{msg.data}]")
        else:
            self.get_logger().info("Lifecycle publisher is inactive. Messages are not published.")
        self.publisher.publish(msg)  # dropped unless the node is active

    def on_configure(self, state: State) -> TransitionCallbackReturn:
        self.publisher = self.create_lifecycle_publisher(String, "lifecycle_chatter", 10)
        self.timer = self.create_timer(0.2, self.tick)
        self.get_logger().info(f"on_configure() is called (from {state.label}).")
        return TransitionCallbackReturn.SUCCESS

    def on_activate(self, state: State) -> TransitionCallbackReturn:
        self.get_logger().info("on_activate() is called.")
        return super().on_activate(state)  # the default one enables the publisher

    def on_deactivate(self, state: State) -> TransitionCallbackReturn:
        self.get_logger().info("on_deactivate() is called.")
        return super().on_deactivate(state)

    def on_cleanup(self, state: State) -> TransitionCallbackReturn:
        self.destroy_timer(self.timer)
        self.timer = None
        self.destroy_lifecycle_publisher(self.publisher)
        self.get_logger().info("on_cleanup() is called.")
        return TransitionCallbackReturn.SUCCESS

    def on_shutdown(self, state: State) -> TransitionCallbackReturn:
        if self.timer is not None:
            self.destroy_timer(self.timer)
        self.get_logger().info(f"on_shutdown() is called (from {state.label}).")
        return TransitionCallbackReturn.SUCCESS


def main(args=None):
    rclpy.init(args=args)
    executor = SingleThreadedExecutor()
    node = LifecycleTalker()
    executor.add_node(node)
    with contextlib.suppress(KeyboardInterrupt, ExternalShutdownException):
        executor.spin()
    node.destroy_node()
    rclpy.try_shutdown()
