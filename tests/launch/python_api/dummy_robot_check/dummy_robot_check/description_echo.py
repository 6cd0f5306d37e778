"""Reads ``robot_description`` and says what it holds (a stand-in for robot_state_publisher)."""

import xml.etree.ElementTree as ET

import rclpy
from rclpy.node import Node


class DescriptionEcho(Node):
    def __init__(self):
        super().__init__("description_echo")
        text = self.declare_parameter("robot_description", "").value
        robot = ET.fromstring(text)
        links = [link.get("name") for link in robot.iter("link")]
        self.get_logger().info(f"robot '{robot.get('name')}' with links: {', '.join(links)}")


def main(args=None):
    rclpy.init(args=args)
    node = DescriptionEcho()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.try_shutdown()
