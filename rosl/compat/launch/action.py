"""launch.action: ``Action`` (for type hints; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.description import Action

__all__ = ["Action"]
__getattr__ = unsupported_names("launch.action", __all__)
