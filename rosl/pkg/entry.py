"""Run one executable of a package: ``python -P -m rosl.pkg.entry PKG_DIR ENTRY NAME [args...]``.

``-P`` keeps the current folder off ``sys.path``: a ``rosl/`` folder there must not shadow rosl.

ENTRY is ``module:function`` (imported with the package folder on ``sys.path``) or a Python
file. rosl's import hooks are installed first, so ``import rclpy`` and
``from std_msgs.msg import String`` work in the executable unchanged.

A ``RoslError`` that ends the executable (a mistake after ``--ros-args``, a domain id out of
range, a broken multicast set-up, a parameter of the wrong type) is one line on stderr, with
the executable's own line that led to it when the mistake may be in the code, and exit 1.
So is a declaration naming a module or function that does not exist (package.xml's line and
the closest names), and an import that fails in the package's own code or names a missing
interface (the importing file and line; ``(did you mean 'MyData'?)``).
Ctrl-C outside ``spin`` exits 130 quietly. Other exceptions are bugs and keep their traceback.
"""

from __future__ import annotations

import importlib
import inspect
import re
import runpy
import sys
from pathlib import Path
from typing import TYPE_CHECKING, cast

if TYPE_CHECKING:
    from collections.abc import Callable
    from types import TracebackType

_ROSL = Path(__file__).resolve().parents[1]


def main(argv: list[str]) -> int:
    """Run the entry point named in ``argv`` and return its exit status."""
    from rosl.errors import RoslError
    from rosl.pkg import interrupts
    from rosl.pkg.errors import ExecutableError

    package_dir = argv[0] if argv else ""
    try:
        interrupts.release()  # a Ctrl-C held since start-up (rosl launch/run) lands here: 130
        return _run(argv)
    except ExecutableError as err:  # package.xml's line already names the executable
        print(str(err), file=sys.stderr)
        return 1
    except RoslError as err:
        from rosl.bus.errors import BusError
        from rosl.node.errors import RosArgsError

        where = "" if isinstance(err, (RosArgsError, BusError)) else _user_line(err.__traceback__)
        message = str(err).splitlines()[0] if str(err) else type(err).__name__
        print(f"{sys.argv[0]}: {where}{message}", file=sys.stderr)
        return 1
    except ImportError as err:
        line = _import_error_line(err, Path(package_dir))
        if line is None:
            raise
        print(f"{sys.argv[0]}: {line}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        interrupts.caught()  # 130, even if the Ctrl-C landed in a class being built
        return 130


def _user_line(trace: TracebackType | None) -> str:
    """``file:line: `` of the innermost frame outside rosl (the executable's own code)."""
    found = ""
    while trace is not None:
        filename = trace.tb_frame.f_code.co_filename
        path = Path(filename)
        if path.is_file() and _ROSL not in path.resolve().parents:
            found = f"{filename}:{trace.tb_lineno}: "
        trace = trace.tb_next
    return found


def _import_error_line(err: ImportError, package_dir: Path) -> str | None:
    """``file:line: message`` for an import that failed in the user's own code, else None.

    A missing interface (``from tutorial_pkg.msg import MyDta``) also says which are close.
    """
    from rosl.compat.interfaces import InterfaceModule
    from rosl.idl.names import did_you_mean

    trace, frame = err.__traceback__, None
    while trace is not None:
        if Path(trace.tb_frame.f_code.co_filename).is_file():
            frame = trace
        trace = trace.tb_next
    if frame is None:
        return None
    path = Path(frame.tb_frame.f_code.co_filename).resolve()
    interface = sys.modules.get(err.name or "")
    if not isinstance(interface, InterfaceModule) and package_dir.resolve() not in path.parents:
        return None  # a library's own import: its traceback is worth keeping
    message = str(err).splitlines()[0]
    missing = re.match(r"cannot import name '([^']+)' from '([^']+)'", message)
    if isinstance(interface, InterfaceModule) and missing:
        message = missing[0] + did_you_mean(missing[1], dir(interface))
    return f"{frame.tb_frame.f_code.co_filename}:{frame.tb_lineno}: {message}"


def _run(argv: list[str]) -> int:
    package_dir, entry, name, *args = argv
    import rosl.compat

    rosl.compat.install(force=True)
    sys.path.insert(0, package_dir)
    sys.argv = [name, *args]
    if entry.endswith(".py") or "/" in entry:
        sys.path.insert(0, str(Path(entry).parent))
        runpy.run_path(entry, run_name="__main__")
        return 0
    module_name, _, function = entry.partition(":")
    main_function = _entry_function(Path(package_dir), name, entry, module_name, function or "main")
    result = main_function()
    return result if isinstance(result, int) else 0


def _entry_function(
    package_dir: Path, name: str, entry: str, module_name: str, function: str
) -> Callable[[], object]:
    """Import ``module_name`` and return its ``function``.

    Raises:
        ExecutableError: no such module or function (``package.xml:line:`` and close names).
    """
    from rosl.idl.names import did_you_mean
    from rosl.pkg.errors import ExecutableError
    from rosl.pkg.manifest import declaration_site

    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as err:
        if err.name is None or not f"{module_name}.".startswith(f"{err.name}."):
            raise  # an import inside the module: reported at its own line
        hint = _module_hint(module_name, _modules(package_dir))
        where = declaration_site(package_dir, name, entry)
        raise ExecutableError(
            f"{where}: executable '{name}': module '{module_name}' not found{hint}"
        ) from None
    found = getattr(module, function, None)
    if not callable(found):
        functions = [
            key
            for key, value in vars(module).items()
            if inspect.isfunction(value) and value.__module__ == module.__name__
        ]
        where = declaration_site(package_dir, name, entry)
        raise ExecutableError(
            f"{where}: executable '{name}': module '{module_name}' has no function "
            f"'{function}'{did_you_mean(function, functions)}"
        )
    return cast("Callable[[], object]", found)


def _module_hint(module_name: str, modules: list[str]) -> str:
    """`` (did you mean 'pkg.x'?)``: a sibling of the same parent first, else any close name."""
    from rosl.idl.names import closest, did_you_mean

    parent, _, leaf = module_name.rpartition(".")
    siblings = {m.rpartition(".")[2]: m for m in modules if m.rpartition(".")[0] == parent}
    near = closest(leaf, list(siblings), n=2)
    if near:
        return " (did you mean " + " or ".join(f"'{siblings[n]}'" for n in near) + "?)"
    for other in closest(parent, {m.rpartition(".")[0] for m in modules}, n=1):
        if f"{other}.{leaf}" in modules:  # the package's name misspelt
            return f" (did you mean '{other}.{leaf}'?)"
    return did_you_mean(module_name, modules)


def _modules(package_dir: Path) -> list[str]:
    """Dotted names of the Python modules in a package folder (two levels down)."""
    found = [p.stem for p in package_dir.glob("*.py")]
    for init in package_dir.glob("*/__init__.py"):
        top = init.parent.name
        found.append(top)
        found.extend(f"{top}.{p.stem}" for p in init.parent.glob("*.py") if p.stem != "__init__")
    return found


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
