"""launch.events: ``Shutdown`` (the event EmitEvent takes)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.actions import Shutdown

__all__ = ["Shutdown"]
__getattr__ = unsupported_names("launch.events", __all__)
