"""rclpy.qos_overriding_options."""

from rosl.node.qos_overrides import (
    InvalidQosOverridesError,
    QosCallbackResult,
    QoSOverridingOptions,
)

__all__ = ["InvalidQosOverridesError", "QoSOverridingOptions", "QosCallbackResult"]
