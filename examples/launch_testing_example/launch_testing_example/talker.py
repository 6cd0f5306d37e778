"""Publishes "Hello World: N" on /chatter; ``count`` messages, then exits (0: forever).

With ``min_subscribers`` it starts only once that many subscriptions listen, so a recorder or
a listener started beside it hears every message.
"""

import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Talker(Node):
    def __init__(self):
        super().__init__("talker")
        self.count = self.declare_parameter("count", 0).value
        self.min_subscribers = self.declare_parameter("min_subscribers", 0).value
        period = self.declare_parameter("period", 0.2).value
        self.publisher = self.create_publisher(String, "chatter", 10)
        self.sent = 0
        self.timer = self.create_timer(period, self.publish_next)

    @property
    def done(self):
        return 0 < self.count <= self.sent

    def publish_next(self):
        if self.done or self.publisher.get_subscription_count() < self.min_subscribers:
            return
        msg = String(data=f"Hello World: {self.sent}")
        self.get_logger().info(f'Publishing: "{msg.data}"')
        self.publisher.publish(msg)
        self.sent += 1


def main(args=None):
    rclpy.init(args=args)
    node = Talker()
    while rclpy.ok() and not node.done:
        rclpy.spin_once(node, timeout_sec=0.1)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
