"""launch.logging (rosl.launch.launch_logging implements it; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.launch_logging import get_logger, reset

__all__ = ["get_logger", "reset"]
__getattr__ = unsupported_names("launch.logging", __all__)
