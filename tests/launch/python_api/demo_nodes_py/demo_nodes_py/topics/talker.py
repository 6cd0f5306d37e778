"""Publishes 'Hello World: N' on chatter once a second."""

import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Talker(Node):
    def __init__(self):
        super().__init__("talker")
        self.count = 0
        self.publisher = self.create_publisher(String, "chatter", 10)
        self.timer = self.create_timer(1.0, self.on_timer)

    def on_timer(self):
        msg = String(data=f"Hello World: {self.count}")
        self.count += 1
        self.get_logger().info(f'Publishing: "{msg.data}"')
        self.publisher.publish(msg)


def main(args=None):
    rclpy.init(args=args)
    node = Talker()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.try_shutdown()
