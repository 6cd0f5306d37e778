"""Prints every MyData message received on /my_data."""

import rclpy
from rclpy.node import Node

from tutorial_pkg.msg import MyData


class MySubscriber(Node):
    def __init__(self):
        super().__init__("my_subscriber")
        self.subscription = self.create_subscription(MyData, "my_data", self.on_data, 10)

    def on_data(self, msg):
        self.get_logger().info(
            f"I heard: counter={msg.counter} value={msg.value:.3f} label='{msg.label}'"
        )


def main(args=None):
    rclpy.init(args=args)
    node = MySubscriber()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
