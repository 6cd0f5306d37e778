"""launch.condition: ``Condition`` (for type hints; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.description import Condition

__all__ = ["Condition"]
__getattr__ = unsupported_names("launch.condition", __all__)
