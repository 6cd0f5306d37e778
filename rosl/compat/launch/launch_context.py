"""launch.launch_context: ``LaunchContext`` (for type hints; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.context import LaunchContext

__all__ = ["LaunchContext"]
__getattr__ = unsupported_names("launch.launch_context", __all__)
