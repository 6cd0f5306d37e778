"""rclpy.signals: rosl installs its own Ctrl-C handling in init(); these are no-ops."""

from enum import IntEnum


class SignalHandlerOptions(IntEnum):
    """Accepted for compatibility."""

    NO = 0
    SIGINT = 1
    SIGTERM = 2
    ALL = 3


__all__ = ["SignalHandlerOptions"]
