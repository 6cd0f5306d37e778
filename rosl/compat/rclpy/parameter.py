"""rclpy.parameter."""

from rosl.node.parameters import Parameter, ParameterType

__all__ = ["Parameter", "ParameterType"]
