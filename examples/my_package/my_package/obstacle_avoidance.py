"""Obstacle avoidance: the second tutorial's node, in Python.

Reads a LaserScan on `laser_scan`, takes the minimum range, and publishes a Twist on
`cmd_vel`: turn in place (0.3 rad/s) when something is closer than 1 m, else drive straight
(0.3 m/s). The launch file remaps both names to Dolly's /dolly/laser_scan and /dolly/cmd_vel.

Parameters not in the tutorial let the same node drive a TurtleBot3, whose LiDAR sees all
around, whose arena is small and whose top speed is 0.22 m/s: `distance_threshold` (default
1.0 m), `field_of_view` (radians around straight ahead; default 0: every reading, as the
tutorial), `linear_speed` and `angular_speed` (defaults 0.3 m/s and 0.3 rad/s, as the tutorial).
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
        self.threshold = self.declare_parameter("distance_threshold", 1.0).value
        self.field_of_view = self.declare_parameter("field_of_view", 0.0).value
        self.linear_speed = self.declare_parameter("linear_speed", 0.3).value
        self.angular_speed = self.declare_parameter("angular_speed", 0.3).value
        self.subscription = self.create_subscription(
            LaserScan, "laser_scan", self.topic_callback, qos_profile_system_default
        )
        self.publisher = self.create_publisher(Twist, "cmd_vel", 10)

    def topic_callback(self, msg):
        # the tutorial's Dolly gives 200 readings from right to left, -57 to +57 degrees
        closest = 10.0
        for index, current in enumerate(msg.ranges):
            if self.field_of_view > 0.0:
                angle = msg.angle_min + index * msg.angle_increment
                angle = math.atan2(math.sin(angle), math.cos(angle))
                if abs(angle) > self.field_of_view / 2:
                    continue
            if not math.isnan(current) and current < closest:
                closest = float(current)
        self.publisher.publish(self.calculate_vel_msg(closest))

    def calculate_vel_msg(self, distance):
        msg = Twist()
        self.get_logger().info(f"Distance is: '{distance:f}'")
        if distance < self.threshold:
            msg.linear.x = 0.0  # turn around
            msg.angular.z = self.angular_speed
        else:
            msg.linear.x = self.linear_speed  # go straight ahead
            msg.angular.z = 0.0
        return msg


def main(args=None):
    rclpy.init(args=args)
    rclpy.spin(ObstacleAvoidance())
    rclpy.shutdown()


if __name__ == "__main__":
    main()
