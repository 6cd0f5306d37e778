"""launch.event_handler: ``EventHandler`` (for type hints; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.event_handlers import EventHandler

__all__ = ["EventHandler"]
__getattr__ = unsupported_names("launch.event_handler", __all__)
