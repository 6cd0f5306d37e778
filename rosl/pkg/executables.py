"""Finding a package's executable and the command line that runs it."""

from __future__ import annotations

import os
import sys

from rosl.idl.names import closest
from rosl.pkg.errors import PackageError
from rosl.pkg.manifest import Executable, get_package


def find_executable(package: str, name: str) -> Executable:
    """Return the executable ``name`` declared by ``package``.

    Raises:
        PackageError: unknown package, or no such executable (the ones it has are listed,
            closest first).
    """
    pkg = get_package(package)
    for executable in pkg.executables:
        if executable.name == name:
            return executable
    if pkg.setup_error:
        raise PackageError(pkg.setup_error)
    names = [e.name for e in pkg.executables]
    module = pkg.path / package / f"{name}.py"
    if module.is_file():  # the seed's pain: written, but never registered
        raise PackageError(
            f"no executable '{name}' in package '{package}': {module} exists but is not "
            f'declared; add <executable name="{name}">{package}.{name}:main</executable> '
            f"under <export><rosl> in {pkg.manifest}"
        )
    if not names:
        raise PackageError(
            f"package '{package}' declares no executables; declare them in "
            f'{pkg.manifest} under <export><rosl><executable name="...">module:main'
            "</executable></rosl></export>"
        )
    near = closest(name, names, n=len(names))
    ordered = near + [n for n in sorted(names) if n not in near]
    raise PackageError(
        f"no executable '{name}' in package '{package}'; it has: {', '.join(ordered)}"
    )


# ``-P``: the current folder stays off sys.path, so a ``rosl/`` folder there (a clone of rosl,
# say) cannot shadow the installed package; the executable's own folders are added by the entry.
_ENTRY = (sys.executable, "-P", "-m", "rosl.pkg.entry")


def command_line(executable: Executable, args: list[str]) -> list[str]:
    """Return the argv that runs ``executable`` with ``args`` in a new process."""
    if executable.is_module:
        return [*_ENTRY, str(executable.package_path), executable.entry, executable.name, *args]
    path = executable.path
    if not path.is_file():
        raise PackageError(
            f"executable '{executable.name}' of package '{executable.package}' points at "
            f"{path}, which does not exist"
        )
    if path.suffix == ".py" or not os.access(path, os.X_OK):
        return [*_ENTRY, str(executable.package_path), str(path), executable.name, *args]
    return [str(path), *args]
