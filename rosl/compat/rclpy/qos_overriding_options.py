"""rclpy.qos_overriding_options."""

from rosl.node.qos_overrides import InvalidQosOverridesError, QoSOverridingOptions

__all__ = ["InvalidQosOverridesError", "QoSOverridingOptions"]
