"""Where packages are found: the ordered search path and the folders with a ``package.xml``.

Order (first wins; later packages of the same name are *shadowed*, not lost):

1. the workspace's ``src/`` — the nearest ancestor of the current directory that has ``src/``
   and is not itself a package; without one, the package the current directory is in and the
   packages directly below the current directory;
2. each entry of ``ROSL_PACKAGE_PATH`` (``os.pathsep``-separated folders);
3. the packages rosl ships: ``interfaces/`` and ``examples/``.

A folder is a package when it holds a ``package.xml``; the package's name is the file's
``<name>``. Scanning does not descend into packages, hidden folders, or folders holding a
``COLCON_IGNORE``/``AMENT_IGNORE`` marker. The result is cached per process (per current
directory and ``ROSL_PACKAGE_PATH``); ``rescan()`` drops the cache.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from rosl.idl.errors import InterfaceError
from rosl.resources import shipped_dir

MANIFEST = "package.xml"
_SKIP_DIRS = {"build", "install", "log", "node_modules", "__pycache__", "site-packages"}
_IGNORE_MARKERS = ("COLCON_IGNORE", "AMENT_IGNORE", "CATKIN_IGNORE")
_MAX_DEPTH = 5


@dataclass(frozen=True, slots=True)
class PackageLocation:
    """A package found on the search path.

    Attributes:
        name: the ``<name>`` from package.xml.
        path: the package folder.
        root: the search-path entry it was found under.
        origin: 'workspace', 'ROSL_PACKAGE_PATH' or 'shipped'.
    """

    name: str
    path: Path
    root: Path
    origin: str

    @property
    def manifest(self) -> Path:
        """The package.xml file."""
        return self.path / MANIFEST


@dataclass(frozen=True, slots=True)
class SearchResult:
    """Every package on the path, first-wins, plus the shadowed and the broken ones."""

    packages: dict[str, PackageLocation]
    shadowed: tuple[tuple[PackageLocation, PackageLocation], ...]  # (hidden, winner)
    broken: tuple[InterfaceError, ...]
    roots: tuple[tuple[Path, str, int], ...]


_cache: dict[tuple[str, str], SearchResult] = {}


def find_workspace(start: Path | None = None) -> Path | None:
    """Return the nearest ancestor of ``start`` with a ``src/`` folder that is not a package."""
    here = (start or Path.cwd()).resolve()
    for folder in (here, *here.parents):
        if (folder / MANIFEST).is_file():
            continue
        if (folder / "src").is_dir():
            return folder
    return None


def search_roots(cwd: Path | None = None) -> list[tuple[Path, str, int]]:
    """Return the ordered search-path entries as (folder, origin, scan depth) triples."""
    here = (cwd or Path.cwd()).resolve()
    roots: list[tuple[Path, str, int]] = []
    workspace = find_workspace(here)
    if workspace is not None:
        roots.append((workspace / "src", "workspace", _MAX_DEPTH))
    else:  # no workspace: the package we are in, and packages right below us
        enclosing = next((f for f in (here, *here.parents) if (f / MANIFEST).is_file()), None)
        if enclosing is not None:
            roots.append((enclosing, "workspace", 0))
        roots.append((here, "workspace", 1))
    for entry in os.environ.get("ROSL_PACKAGE_PATH", "").split(os.pathsep):
        if entry.strip():
            roots.append((Path(entry).expanduser().resolve(), "ROSL_PACKAGE_PATH", _MAX_DEPTH))
    for name in ("interfaces", "worlds", "examples"):
        try:
            roots.append((shipped_dir(name), "shipped", 2))
        except FileNotFoundError:
            continue
    return roots


def read_package_name(manifest: Path) -> str:
    """Read ``<name>`` from a package.xml.

    Raises:
        InterfaceError: the file is not XML, or has no usable ``<name>``.
    """
    import xml.etree.ElementTree as ET  # only where a package.xml is read

    try:
        root = ET.parse(manifest).getroot()
    except ET.ParseError as err:
        line, col = err.position
        raise InterfaceError(
            f"package.xml is not well-formed XML ({err.msg.split(':')[0]})", manifest, line, col + 1
        ) from None
    except OSError as err:
        raise InterfaceError(f"cannot read package.xml: {err.strerror}", manifest) from None
    name = root.findtext("name")
    if root.tag != "package" or not name or not name.strip():
        raise InterfaceError(
            "package.xml has no <name> inside <package>; add <name>your_package</name>", manifest
        )
    return name.strip()


def _scan(root: Path, depth: int) -> list[Path]:
    if not root.is_dir() or any((root / m).exists() for m in _IGNORE_MARKERS):
        return []
    if (root / MANIFEST).is_file():
        return [root]
    if depth <= 0:
        return []
    found: list[Path] = []
    try:
        children = sorted(root.iterdir())
    except OSError:
        return []
    for child in children:
        if child.name.startswith(".") or child.name in _SKIP_DIRS or not child.is_dir():
            continue
        found.extend(_scan(child, depth - 1))
    return found


def scan(cwd: Path | None = None) -> SearchResult:
    """Find every package on the search path (cached per directory and environment)."""
    here = (cwd or Path.cwd()).resolve()
    key = (str(here), os.environ.get("ROSL_PACKAGE_PATH", ""))
    if key in _cache:
        return _cache[key]
    packages: dict[str, PackageLocation] = {}
    shadowed: list[tuple[PackageLocation, PackageLocation]] = []
    broken: list[InterfaceError] = []
    seen: set[Path] = set()
    roots = search_roots(here)
    for root, origin, depth in roots:
        for folder in _scan(root, depth):
            if folder in seen:
                continue
            seen.add(folder)
            try:
                name = read_package_name(folder / MANIFEST)
            except InterfaceError as err:
                broken.append(err)
                continue
            location = PackageLocation(name, folder, root, origin)
            if name in packages:
                shadowed.append((location, packages[name]))
            else:
                packages[name] = location
    result = SearchResult(packages, tuple(shadowed), tuple(broken), tuple(roots))
    _cache[key] = result
    return result


def rescan() -> None:
    """Forget cached scans, e.g. after creating a package."""
    _cache.clear()


def find_package(name: str) -> PackageLocation:
    """Return the package called ``name``.

    Raises:
        InterfaceError: no such package; the message lists close names and where it looked.
    """
    result = scan()
    if name in result.packages:
        return result.packages[name]
    for err in result.broken:
        if err.path is not None and err.path.parent.name == name:
            raise err
    raise InterfaceError(unknown_package_message(name, result))


def unknown_package_message(name: str, result: SearchResult) -> str:
    """The one-line text for a package that is not on the search path."""
    from rosl.idl.names import did_you_mean

    where = ", ".join(str(root) for root, _, _ in result.roots if root.is_dir())
    text = f"package '{name}' not found{did_you_mean(name, set(result.packages))}; searched {where}"
    elsewhere = _in_another_workspace(name)
    if elsewhere is not None:
        src = elsewhere.parent
        text += (
            f"; it is in {elsewhere}, a workspace not active here: run rosl from inside "
            f"{src.parent} or export ROSL_PACKAGE_PATH={src}"
        )
    return text


def _in_another_workspace(name: str) -> Path | None:
    """``~/<workspace>/src/<name>`` when such a package exists (the seed's ``~/ros2_ws``)."""
    try:
        candidates = sorted(Path.home().glob(f"*/src/{name}/{MANIFEST}"))
    except (OSError, RuntimeError):  # no home, or one rosl may not read
        return None
    return candidates[0].parent if candidates else None
