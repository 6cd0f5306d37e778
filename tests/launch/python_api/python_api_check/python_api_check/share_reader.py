"""Prints what ament_index_python says about this package, from inside a node's process."""

from pathlib import Path

from ament_index_python.packages import (
    PackageNotFoundError,
    get_package_prefix,
    get_package_share_directory,
    get_package_share_path,
)


def main():
    share = get_package_share_directory("python_api_check")
    config = get_package_share_path("python_api_check") / "config" / "timer.yaml"
    print(f"share_reader: share={share} prefix={get_package_prefix('python_api_check')}")
    print(
        f"share_reader: config found={config.is_file()} same={Path(share) / 'config' / 'timer.yaml' == config}"
    )
    try:
        get_package_share_directory("no_such_package")
    except PackageNotFoundError as err:
        print(f"share_reader: missing package: {err}")
