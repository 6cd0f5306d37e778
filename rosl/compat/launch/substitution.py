"""launch.substitution: ``Substitution`` (for type hints; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.substitutions import Substitution

__all__ = ["Substitution"]
__getattr__ = unsupported_names("launch.substitution", __all__)
