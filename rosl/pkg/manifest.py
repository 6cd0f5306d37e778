"""package.xml: what a package declares (name, version, dependencies, executables).

Executables are declared in one place, package.xml, with no install step::

    <export>
      <rosl>
        <executable name="my_publisher">tutorial_pkg.my_publisher:main</executable>
        <executable name="tool">scripts/tool.py</executable>
      </rosl>
    </export>

The text is either ``module:function`` (the module is imported from the package folder) or a
file path relative to the package. Packages written for ROS 2 (``ament_python``) that have no
such block still work: their ``setup.py``/``setup.cfg`` ``console_scripts`` are read
statically.
"""

from __future__ import annotations

import configparser
import contextlib
import xml.etree.ElementTree as ET
import xml.parsers.expat
from dataclasses import dataclass, field
from pathlib import Path

from rosl.idl import search_path
from rosl.idl.errors import InterfaceError
from rosl.pkg import setup_py as setup_py_reader
from rosl.pkg.errors import PackageError

_DEPEND_TAGS = ("depend", "exec_depend", "build_depend", "buildtool_depend", "test_depend")


@dataclass(frozen=True, slots=True)
class Executable:
    """A runnable entry point of a package.

    Attributes:
        package: the package name.
        name: what the user types after the package name.
        entry: ``module:function`` or a path relative to the package folder.
        package_path: the package folder.
    """

    package: str
    name: str
    entry: str
    package_path: Path

    @property
    def is_module(self) -> bool:
        """Whether the entry is ``module:function`` (else a file)."""
        return ":" in self.entry and "/" not in self.entry.split(":", 1)[0]

    @property
    def path(self) -> Path:
        """The file that implements it."""
        if self.is_module:
            module = self.entry.split(":", 1)[0]
            base = self.package_path / Path(*module.split("."))
            return base.with_suffix(".py") if not base.is_dir() else base / "__init__.py"
        return self.package_path / self.entry


@dataclass(frozen=True, slots=True)
class Package:
    """A package and what its package.xml says."""

    name: str
    path: Path
    origin: str
    version: str = ""
    description: str = ""
    license: str = ""
    build_type: str = ""
    maintainers: tuple[str, ...] = ()
    dependencies: tuple[str, ...] = ()
    executables: tuple[Executable, ...] = field(default_factory=tuple)
    setup_error: str = ""  # setup.py's console_scripts could not be read (file:line: why)

    @property
    def manifest(self) -> Path:
        """The package.xml file."""
        return self.path / search_path.MANIFEST


def load(location: search_path.PackageLocation) -> Package:
    """Read a package's manifest.

    Raises:
        PackageError: package.xml is not well-formed (with file:line:col).
    """
    try:
        root = ET.parse(location.manifest).getroot()
    except ET.ParseError as err:
        line, col = err.position
        raise PackageError(
            f"{location.manifest}:{line}:{col + 1}: package.xml is not well-formed XML"
        ) from None
    deps: list[str] = []
    for tag in _DEPEND_TAGS:
        deps.extend(e.text.strip() for e in root.iter(tag) if e.text and e.text.strip())
    maintainers = tuple(
        f"{(e.text or '').strip()} <{e.get('email', '')}>" for e in root.iter("maintainer")
    )
    executables = tuple(
        Executable(location.name, e.get("name", "").strip(), (e.text or "").strip(), location.path)
        for e in root.iterfind("export/rosl/executable")
        if e.get("name") and e.text
    )
    setup_error = ""
    if not executables:
        executables, setup_error = _setup_console_scripts(location)
    return Package(
        name=location.name,
        path=location.path,
        origin=location.origin,
        version=(root.findtext("version") or "").strip(),
        description=" ".join((root.findtext("description") or "").split()),
        license=", ".join((e.text or "").strip() for e in root.iter("license")),
        build_type=(root.findtext("export/build_type") or "").strip(),
        maintainers=maintainers,
        dependencies=tuple(dict.fromkeys(deps)),
        executables=executables,
        setup_error=setup_error,
    )


def _setup_console_scripts(
    location: search_path.PackageLocation,
) -> tuple[tuple[Executable, ...], str]:
    """``console_scripts`` of an ament_python package's setup.py/setup.cfg, and any error.

    The error (setup.py that cannot be read without running it) is kept, not raised: the
    package still lists, and running one of its executables reports it.
    """
    found: list[str] = []
    error = ""
    setup_py = location.path / "setup.py"
    if setup_py.is_file():
        try:
            found.extend(setup_py_reader.console_scripts(setup_py))
        except PackageError as err:
            error = str(err)
    setup_cfg = location.path / "setup.cfg"
    if setup_cfg.is_file():
        parser = configparser.ConfigParser()
        try:
            parser.read(setup_cfg, encoding="utf-8")
            text = parser.get("options.entry_points", "console_scripts", fallback="")
        except configparser.Error:
            text = ""
        found.extend(line for line in text.splitlines() if "=" in line)
    executables = []
    for spec in found:
        name, _, entry = str(spec).partition("=")
        if name.strip() and entry.strip():
            executables.append(
                Executable(location.name, name.strip(), entry.strip(), location.path)
            )
    return tuple(executables), error


def declaration_site(package_path: Path, name: str, entry: str) -> str:
    """Return ``file:line`` where executable ``name`` is declared (``file`` if no line is known).

    package.xml's ``<executable name="...">`` comes first, then a ``console_scripts`` line of
    setup.py or setup.cfg that holds ``entry``.
    """
    manifest = package_path / search_path.MANIFEST
    lines: dict[str, int] = {}
    parser = xml.parsers.expat.ParserCreate()

    def start(tag: str, attributes: dict[str, str]) -> None:
        if tag == "executable" and "name" in attributes:
            lines.setdefault(attributes["name"].strip(), parser.CurrentLineNumber)

    parser.StartElementHandler = start
    with contextlib.suppress(OSError, xml.parsers.expat.ExpatError):
        parser.Parse(manifest.read_bytes(), True)
    if name in lines:
        return f"{manifest}:{lines[name]}"
    setup_lines = setup_py_reader.console_script_lines(package_path / "setup.py")
    if name in setup_lines:  # also an entry built in code ('x = ' + package_name + ...)
        return f"{package_path / 'setup.py'}:{setup_lines[name]}"
    for setup in (package_path / "setup.py", package_path / "setup.cfg"):
        try:
            text = setup.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            continue
        for number, line in enumerate(text.splitlines(), start=1):
            if entry in line and name in line:
                return f"{setup}:{number}"
    return str(manifest)


def get_package(name: str) -> Package:
    """Return the package called ``name`` from the search path.

    Raises:
        PackageError: no such package (close names and the folders searched are listed).
    """
    try:
        location = search_path.find_package(name)
    except InterfaceError as err:
        raise PackageError(str(err)) from None
    return load(location)


def list_packages() -> list[Package]:
    """Return every package on the search path (first of each name), sorted by name."""
    result = search_path.scan()
    return [load(result.packages[name]) for name in sorted(result.packages)]
