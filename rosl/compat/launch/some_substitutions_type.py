"""launch.some_substitutions_type: ``SomeSubstitutionsType`` (a type hint; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.substitutions import SomeSubstitutions as SomeSubstitutionsType

__all__ = ["SomeSubstitutionsType"]
__getattr__ = unsupported_names("launch.some_substitutions_type", __all__)
