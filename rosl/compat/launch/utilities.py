"""launch.utilities: ``perform_substitutions`` and ``normalize_to_list_of_substitutions``."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.substitutions import normalize as normalize_to_list_of_substitutions
from rosl.launch.substitutions import perform as perform_substitutions

__all__ = ["normalize_to_list_of_substitutions", "perform_substitutions"]
__getattr__ = unsupported_names("launch.utilities", __all__)
