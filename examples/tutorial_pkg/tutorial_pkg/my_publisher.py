"""Publishes a MyData message on /my_data once a second."""

import math

import rclpy
from rclpy.node import Node

from tutorial_pkg.msg import MyData


class MyPublisher(Node):
    def __init__(self):
        super().__init__("my_publisher")
        self.publisher = self.create_publisher(MyData, "my_data", 10)
        self.counter = 0
        self.timer = self.create_timer(1.0, self.publish_reading)

    def publish_reading(self):
        self.counter += 1
        msg = MyData(counter=self.counter, value=math.sin(self.counter / 10.0), label="reading")
        self.publisher.publish(msg)
        self.get_logger().info(f"Publishing: counter={msg.counter} value={msg.value:.3f}")


def main(args=None):
    rclpy.init(args=args)
    node = MyPublisher()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
