"""launch.event_handlers."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.event_handlers import (
    OnExecutionComplete,
    OnProcessExit,
    OnProcessIO,
    OnProcessStart,
    OnShutdown,
)

__all__ = ["OnExecutionComplete", "OnProcessExit", "OnProcessIO", "OnProcessStart", "OnShutdown"]
__getattr__ = unsupported_names("launch.event_handlers", __all__)
