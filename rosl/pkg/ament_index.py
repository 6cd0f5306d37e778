"""ament_index_python.packages under rosl: a package folder stands for its prefix and share."""

from __future__ import annotations

from pathlib import Path

from rosl.errors import RoslError
from rosl.pkg.errors import PackageError
from rosl.pkg.manifest import get_package, list_packages

__all__ = [
    "PackageNotFoundError",
    "get_package_prefix",
    "get_package_share_directory",
    "get_package_share_path",
    "get_packages_with_prefixes",
]


class PackageNotFoundError(KeyError, RoslError):
    """No package of that name on rosl's package path (a KeyError, as ament's is)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


def get_package_prefix(package_name: str) -> str:
    """The package's folder.

    Raises:
        PackageNotFoundError: no such package (close names and the folders searched listed).
    """
    try:
        return str(get_package(package_name).path)
    except PackageError as err:
        raise PackageNotFoundError(str(err)) from None


def get_package_share_directory(package_name: str, print_warning: bool = True) -> str:
    """The package's folder (what ROS 2 installs to ``share/<package>``)."""
    del print_warning
    return get_package_prefix(package_name)


def get_package_share_path(package_name: str, print_warning: bool = True) -> Path:
    """The package's folder as a Path."""
    del print_warning
    return Path(get_package_prefix(package_name))


def get_packages_with_prefixes() -> dict[str, str]:
    """Every package on the path and its folder."""
    return {package.name: str(package.path) for package in list_packages()}
