"""``rosl pkg create``: a package usable the moment it is written — no build, no install.

The layout follows ``ros2 pkg create --build-type ament_python`` minus the packaging files
rosl does not need: package.xml (with the executables declared in it), ``msg/``, ``srv/``,
``launch/`` and the Python module; with a node name, a runnable rclpy-style node.
"""

from __future__ import annotations

import getpass
import subprocess
from dataclasses import dataclass
from typing import TYPE_CHECKING
from xml.sax.saxutils import escape

from rosl.idl import search_path
from rosl.idl.names import PACKAGE_NAME
from rosl.pkg.errors import PackageError

if TYPE_CHECKING:
    from pathlib import Path

DEFAULT_DESCRIPTION = "TODO: Package description"
DEFAULT_LICENSE = "TODO: License declaration"
BUILD_TYPES = ("ament_python", "ament_cmake", "cmake")


@dataclass(frozen=True, slots=True)
class PackageRequest:
    """What the user asked ``pkg create`` for."""

    name: str
    destination: Path
    dependencies: tuple[str, ...] = ()
    node_name: str | None = None
    description: str = DEFAULT_DESCRIPTION
    license: str = DEFAULT_LICENSE
    build_type: str = "ament_python"
    maintainer_name: str | None = None
    maintainer_email: str | None = None


def _git_config(key: str) -> str:
    try:
        out = subprocess.run(
            ["git", "config", "--global", key],
            capture_output=True,
            text=True,
            timeout=2,
            check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return ""
    return out.stdout.strip()


def maintainer(request: PackageRequest) -> tuple[str, str]:
    """Return (name, email) for package.xml, as ros2 pkg create picks them."""
    name = request.maintainer_name or _git_config("user.name") or getpass.getuser()
    email = request.maintainer_email or _git_config("user.email") or f"{name}@todo.todo"
    return name, email


def summary(request: PackageRequest) -> list[str]:
    """Return the lines ``ros2 pkg create`` prints before writing anything."""
    name, email = maintainer(request)
    return [
        "going to create a new package",
        f"package name: {request.name}",
        f"destination directory: {request.destination}",
        "package format: 3",
        "version: 0.0.0",
        f"description: {request.description}",
        f"maintainer: ['{name} <{email}>']",
        f"licenses: ['{request.license}']",
        f"build type: {request.build_type}",
        f"dependencies: {list(request.dependencies)}",
        *([f"node_name: {request.node_name}"] if request.node_name else []),
    ]


def validate(request: PackageRequest) -> None:
    """Reject names ROS 2 rejects and destinations that already exist."""
    if not PACKAGE_NAME.match(request.name):
        raise PackageError(
            f"invalid package name '{request.name}': use lowercase letters, digits and single "
            "underscores, starting with a letter"
        )
    if request.node_name is not None and not PACKAGE_NAME.match(request.node_name):
        raise PackageError(
            f"invalid node name '{request.node_name}': use lowercase letters, digits and "
            "underscores, starting with a letter"
        )
    target = request.destination / request.name
    if target.exists():
        raise PackageError(f"Aborted! The directory already exists: {target}")


def package_xml(request: PackageRequest) -> str:
    """Return the package.xml text for a new package."""
    name, email = maintainer(request)
    deps = "".join(f"  <depend>{escape(d)}</depend>\n" for d in request.dependencies)
    executables = ""
    if request.node_name:
        executables = (
            f'      <executable name="{request.node_name}">'
            f"{request.name}.{request.node_name}:main</executable>\n"
        )
    return (
        '<?xml version="1.0"?>\n'
        '<?xml-model href="http://download.ros.org/schema/package_format3.xsd" '
        'schematypens="http://www.w3.org/2001/XMLSchema"?>\n'
        '<package format="3">\n'
        f"  <name>{request.name}</name>\n"
        "  <version>0.0.0</version>\n"
        f"  <description>{escape(request.description)}</description>\n"
        f'  <maintainer email="{escape(email)}">{escape(name)}</maintainer>\n'
        f"  <license>{escape(request.license)}</license>\n"
        + ("\n" + deps if deps else "")
        + "\n  <export>\n"
        f"    <build_type>{request.build_type}</build_type>\n"
        "    <rosl>\n"
        "      <!-- `rosl run "
        + request.name
        + " NAME` runs these; no build or install step -->\n"
        + executables
        + "    </rosl>\n"
        "  </export>\n"
        "</package>\n"
    )


def node_source(package: str, node: str) -> str:
    """Return a small runnable rclpy-style node for ``--node-name``."""
    cls = "".join(part.capitalize() for part in node.split("_"))
    return f'''"""{node}: a node of {package}. Run it with `rosl run {package} {node}`."""

import rclpy
from rclpy.node import Node


class {cls}(Node):
    def __init__(self):
        super().__init__("{node}")
        self.count = 0
        self.timer = self.create_timer(1.0, self.on_timer)

    def on_timer(self):
        self.count += 1
        self.get_logger().info(f"Hi from {package} ({{self.count}})")


def main(args=None):
    rclpy.init(args=args)
    node = {cls}()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
'''


def plan(request: PackageRequest) -> list[tuple[Path, str | None]]:
    """Return the (path, content) pairs to write; content ``None`` means a folder."""
    root = request.destination / request.name
    entries: list[tuple[Path, str | None]] = [
        (root, None),
        (root / "package.xml", package_xml(request)),
        (root / request.name, None),
        (root / request.name / "__init__.py", ""),
    ]
    if request.node_name:
        entries.append(
            (
                root / request.name / f"{request.node_name}.py",
                node_source(request.name, request.node_name),
            )
        )
    entries += [(root / "msg", None), (root / "srv", None), (root / "launch", None)]
    return entries


def create(request: PackageRequest) -> list[tuple[Path, str | None]]:
    """Write the package; return what was written, in order.

    Raises:
        PackageError: invalid name or an existing destination; nothing is written then.
    """
    validate(request)
    entries = plan(request)
    try:
        for path, content in entries:
            if content is None:
                path.mkdir(parents=True, exist_ok=False)
            else:
                path.write_text(content, encoding="utf-8")
    except OSError as err:
        raise PackageError(f"cannot create {err.filename}: {err.strerror}") from None
    search_path.rescan()
    return entries
