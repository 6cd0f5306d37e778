"""Asks add_two_ints for 2 + 3 once, prints the result and exits."""

import rclpy
from example_interfaces.srv import AddTwoInts


def main(args=None):
    rclpy.init(args=args)
    node = rclpy.create_node("add_two_ints_client")
    client = node.create_client(AddTwoInts, "add_two_ints")
    for _ in range(30):  # a bounded wait for the server
        if client.wait_for_service(timeout_sec=1.0):
            break
        node.get_logger().info("service not available, waiting again...")
    else:
        node.get_logger().error("add_two_ints never came up")
        return 1
    request = AddTwoInts.Request(a=2, b=3)
    future = client.call_async(request)
    rclpy.spin_until_future_complete(node, future, timeout_sec=30.0)
    if future.result() is None:
        node.get_logger().error("no answer from add_two_ints")
        return 1
    total = future.result().sum
    node.get_logger().info(f"Result of add_two_ints: for {request.a} + {request.b} = {total}")
    node.destroy_node()
    rclpy.shutdown()
    return 0
