"""ament_index_python.packages (rosl.pkg.ament_index implements it; no logic here)."""

from rosl.compat.unsupported import unsupported_names
from rosl.pkg.ament_index import (
    PackageNotFoundError,
    get_package_prefix,
    get_package_share_directory,
    get_package_share_path,
    get_packages_with_prefixes,
)

__all__ = [
    "PackageNotFoundError",
    "get_package_prefix",
    "get_package_share_directory",
    "get_package_share_path",
    "get_packages_with_prefixes",
]
__getattr__ = unsupported_names("ament_index_python.packages", __all__)
