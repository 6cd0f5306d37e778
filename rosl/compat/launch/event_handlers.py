"""launch.event_handlers."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.actions import OnProcessExit, OnProcessStart

__all__ = ["OnProcessExit", "OnProcessStart"]
__getattr__ = unsupported_names("launch.event_handlers", __all__)
