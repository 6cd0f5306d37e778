"""rclpy.parameter_client."""

from rosl.node.parameter_client import AsyncParameterClient

__all__ = ["AsyncParameterClient"]
