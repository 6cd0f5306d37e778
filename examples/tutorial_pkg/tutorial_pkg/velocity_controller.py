"""The first tutorial's square driver: a 100 ms timer alternates two phases on /cmd_vel.

Forward at 0.2 m/s for 20 ticks (2 s), then turn at 0.5 rad/s for 16 ticks (~90 degrees).

rosl launch tutorial_pkg square.launch.py        (the simulator and this node, with a picture)
rosl run tutorial_pkg velocity_controller        (against a running `rosl sim empty`)
"""

import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node


class VelocityController(Node):
    def __init__(self):
        super().__init__("velocity_controller")
        self.publisher = self.create_publisher(Twist, "/cmd_vel", 10)
        self.phase = 0
        self.step = 0
        self.timer = self.create_timer(0.1, self.on_timer)  # fires every 100 ms

    def on_timer(self):
        msg = Twist()
        if self.phase == 0:
            msg.linear.x = 0.2  # forward at 0.2 m/s
            msg.angular.z = 0.0
            self.step += 1
            if self.step >= 20:  # 2 seconds forward
                self.phase, self.step = 1, 0
        else:
            msg.linear.x = 0.0
            msg.angular.z = 0.5  # turn at 0.5 rad/s
            self.step += 1
            if self.step >= 16:  # ~90 degrees
                self.phase, self.step = 0, 0
        self.publisher.publish(msg)


def main(args=None):
    rclpy.init(args=args)
    node = VelocityController()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
