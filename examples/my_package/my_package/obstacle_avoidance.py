"""Obstacle avoidance: the second tutorial's node, in Python.

Reads a LaserScan on `laser_scan`, takes the minimum range, and publishes a Twist on
`cmd_vel`: turn in place (0.3 rad/s) when something is closer than 1 m, else drive straight
(0.3 m/s). The launch file remaps both names to Dolly's /dolly/laser_scan and /dolly/cmd_vel.
"""

import math

import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.qos import qos_profile_system_default
from sensor_msgs.msg import LaserScan


class ObstacleAvoidance(Node):
    def __init__(self):
        super().__init__("ObstacleAvoidance")
        self.subscription = self.create_subscription(
            LaserScan, "laser_scan", self.topic_callback, qos_profile_system_default
        )
        self.publisher = self.create_publisher(Twist, "cmd_vel", 10)

    def topic_callback(self, msg):
        # the tutorial's Dolly gives 200 readings from right to left, -57 to +57 degrees
        closest = 10.0
        for current in msg.ranges:
            if not math.isnan(current) and current < closest:
                closest = float(current)
        self.publisher.publish(self.calculate_vel_msg(closest))

    def calculate_vel_msg(self, distance):
        msg = Twist()
        self.get_logger().info(f"Distance is: '{distance:f}'")
        if distance < 1:
            msg.linear.x = 0.0  # turn around
            msg.angular.z = 0.3
        else:
            msg.linear.x = 0.3  # go straight ahead
            msg.angular.z = 0.0
        return msg


def main(args=None):
    rclpy.init(args=args)
    rclpy.spin(ObstacleAvoidance())
    rclpy.shutdown()


if __name__ == "__main__":
    main()
