"""launch_ros.event_handlers: OnStateTransition."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.lifecycle_events import OnStateTransition

__all__ = ["OnStateTransition"]
__getattr__ = unsupported_names("launch_ros.event_handlers", __all__)
