"""Publishes numbered messages of a chosen payload size with chosen QoS, on '<name>_data'."""

import argparse
import sys

import rclpy
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.utilities import remove_ros_args
from std_msgs.msg import String


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("data_name", nargs="?", default="topic1")
    parser.add_argument("-p", "--payload-size", type=int, default=0)
    parser.add_argument("--period", type=float, default=0.5)
    parser.add_argument("--depth", type=int, default=10)
    parser.add_argument("--best-effort", action="store_true")
    args = parser.parse_args(remove_ros_args(args=sys.argv)[1:])

    rclpy.init(args=sys.argv)
    node = rclpy.create_node(f"{args.data_name}_pub")
    reliability = ReliabilityPolicy.BEST_EFFORT if args.best_effort else ReliabilityPolicy.RELIABLE
    qos = QoSProfile(depth=args.depth, reliability=reliability)
    topic = f"{args.data_name}_data"
    publisher = node.create_publisher(String, topic, qos)
    payload = "x" * args.payload_size
    count = 0

    def publish():
        nonlocal count
        count += 1
        publisher.publish(String(data=f"{count}:{payload}"))
        node.get_logger().info(
            f"Publishing on '{topic}': #{count} ({args.payload_size}-byte payload, "
            f"depth {args.depth}, {reliability.name.lower()})"
        )

    node.create_timer(args.period, publish)
    rclpy.spin(node)
    node.destroy_node()
    rclpy.try_shutdown()
