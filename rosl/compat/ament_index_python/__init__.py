"""``import ament_index_python`` under rosl: packages found on rosl's package path.

rosl installs nothing, so a package's prefix and its share directory are both the package's
folder (where its ``package.xml`` is): ``get_package_share_directory('pkg') + '/launch/...'``
finds the files a ROS 2 package would install there.
"""

from rosl.compat.ament_index_python.packages import (
    PackageNotFoundError,
    get_package_prefix,
    get_package_share_directory,
    get_package_share_path,
    get_packages_with_prefixes,
)
from rosl.compat.unsupported import unsupported_names

__all__ = [
    "PackageNotFoundError",
    "get_package_prefix",
    "get_package_share_directory",
    "get_package_share_path",
    "get_packages_with_prefixes",
]
__getattr__ = unsupported_names("ament_index_python", __all__)
