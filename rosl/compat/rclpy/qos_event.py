"""rclpy.qos_event (Humble's name; Jazzy calls it rclpy.event_handler): the same names."""

from rosl.compat.rclpy.event_handler import *  # noqa: F403
from rosl.compat.rclpy.event_handler import __all__ as __all__
