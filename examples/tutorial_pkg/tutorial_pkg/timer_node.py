"""A timer whose period is the parameter timer_period_s (default 2.0 s), changeable live:

rosl run tutorial_pkg timer_node --ros-args -p timer_period_s:=1.0
rosl param set /timer_node timer_period_s 0.5
"""

import rclpy
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node


class TimerNode(Node):
    def __init__(self):
        super().__init__("timer_node")
        self.declare_parameter("timer_period_s", 2.0)
        period = self.get_parameter("timer_period_s").as_double()
        self.ticks = 0
        self.timer = self.create_timer(period, self.on_timer)
        self.add_on_set_parameters_callback(self.on_parameters)
        self.get_logger().info(f"Timer period: {period} s")

    def on_timer(self):
        self.ticks += 1
        period = self.timer.timer_period_ns / 1e9
        self.get_logger().info(f"Tick {self.ticks} (period {period} s)")

    def on_parameters(self, params):
        for param in params:
            if param.name == "timer_period_s":
                if param.value <= 0.0:
                    return SetParametersResult(
                        successful=False, reason="timer_period_s must be > 0"
                    )
                self.timer.timer_period_ns = int(param.value * 1e9)
                self.get_logger().info(f"Timer period changed to {param.value} s")
        return SetParametersResult(successful=True)


def main(args=None):
    rclpy.init(args=args)
    node = TimerNode()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
