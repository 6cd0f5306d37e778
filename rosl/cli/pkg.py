"""``rosl pkg``: create, list, executables, prefix, xml."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import click

from rosl.cli import render
from rosl.cli.options import GreedyOption
from rosl.idl import search_path
from rosl.pkg import create as scaffold
from rosl.pkg import manifest
from rosl.pkg.errors import PackageError


@click.group("pkg")
def command() -> None:
    """Various package related sub-commands."""


@command.command("create")
@click.argument("package_name")
@click.option("--package-format", type=click.Choice(["2", "3"]), default="3", help="Ignored.")
@click.option("--description", default=scaffold.DEFAULT_DESCRIPTION, help="For package.xml.")
@click.option("--license", "license_", default=scaffold.DEFAULT_LICENSE, help="For package.xml.")
@click.option(
    "--destination-directory",
    type=click.Path(file_okay=False, path_type=Path),
    default=Path("."),
    help="Directory where to create the package directory.",
)
@click.option(
    "--build-type",
    type=click.Choice(scaffold.BUILD_TYPES),
    default="ament_python",
    help="Recorded in package.xml; rosl builds nothing either way.",
)
@click.option(
    "--dependencies", cls=GreedyOption, multiple=True, help="Dependencies, e.g. std_msgs rclpy."
)
@click.option("--maintainer-email", default=None, help="Email address of the maintainer.")
@click.option("--maintainer-name", default=None, help="Name of the maintainer.")
@click.option("--node-name", default=None, help="Name of a runnable example node to write.")
def create(package_name: str, **options: Any) -> None:
    """Create a new package: usable at once, no build and no sourcing."""
    request = scaffold.PackageRequest(
        name=package_name,
        destination=options["destination_directory"].resolve(),
        dependencies=tuple(dict.fromkeys(options["dependencies"])),
        node_name=options["node_name"],
        description=options["description"],
        license=options["license_"],
        build_type=options["build_type"],
        maintainer_name=options["maintainer_name"],
        maintainer_email=options["maintainer_email"],
    )
    scaffold.validate(request)
    render.lines(scaffold.summary(request))
    for path, content in scaffold.create(request):
        relative = "./" + str(path.relative_to(request.destination))
        render.text(f"creating {'folder ' if content is None else ''}{relative}\n")
    if request.build_type != "ament_python":
        render.warn(f"note: rosl compiles nothing; '{request.build_type}' is only recorded")


@command.command("list")
@click.option("-v", "--verbose", is_flag=True, help="Also show folders and shadowed packages.")
def list_(verbose: bool) -> int:
    """Output a list of available packages."""
    result = search_path.scan()
    if not verbose:
        render.lines(sorted(result.packages))
    else:
        for name in sorted(result.packages):
            location = result.packages[name]
            render.text(f"{name}  {location.path}  ({location.origin})\n")
        for hidden, winner in result.shadowed:
            render.text(f"{hidden.name}  {hidden.path}  (shadowed by {winner.path})\n")
    for err in result.broken:
        render.warn(f"warning: {err}")
    return 1 if result.broken else 0


@command.command("executables")
@click.argument("package_name", required=False)
@click.option("--full-path", is_flag=True, help="Show the full path of each executable")
def executables(package_name: str | None, full_path: bool) -> None:
    """Output a list of package specific executables."""
    packages = [manifest.get_package(package_name)] if package_name else manifest.list_packages()
    if package_name and packages[0].setup_error:
        raise PackageError(packages[0].setup_error)
    rows = []
    for pkg in packages:
        for exe in sorted(pkg.executables, key=lambda e: e.name):
            rows.append(str(exe.path) if full_path else f"{pkg.name} {exe.name}")
    render.lines(rows)


@command.command("prefix")
@click.argument("package_name")
@click.option("--share", is_flag=True, help="Show share directory for the package")
def prefix(package_name: str, share: bool) -> None:
    """Output the prefix path of a package (its folder: rosl has no install space)."""
    del share
    render.text(f"{manifest.get_package(package_name).path}\n")


@command.command("xml")
@click.argument("package_name")
@click.option("-t", "--tag", default=None, help="The XML tag to output (e.g. 'version')")
def xml(package_name: str, tag: str | None) -> None:
    """Output the XML of the package manifest or a specific tag."""
    pkg = manifest.get_package(package_name)
    text = pkg.manifest.read_text(encoding="utf-8")
    if tag is None:
        render.text(text)
        return
    values = [(e.text or "").strip() for e in ET.fromstring(text).iter(tag)]
    if not values:
        raise PackageError(f"package.xml of '{package_name}' has no <{tag}> tag")
    render.lines(values)
