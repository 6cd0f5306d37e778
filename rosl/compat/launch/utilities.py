"""launch.utilities: ``perform_substitutions`` (what OpaqueFunction code calls)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.substitutions import perform as perform_substitutions

__all__ = ["perform_substitutions"]
__getattr__ = unsupported_names("launch.utilities", __all__)
