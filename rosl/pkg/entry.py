"""Run one executable of a package: ``python -m rosl.pkg.entry PKG_DIR ENTRY NAME [args...]``.

ENTRY is ``module:function`` (imported with the package folder on ``sys.path``) or a Python
file. rosl's import hooks are installed first, so ``import rclpy`` and
``from std_msgs.msg import String`` work in the executable unchanged.

A ``RoslError`` that ends the executable (a mistake after ``--ros-args``, a domain id out of
range, a broken multicast set-up, a parameter of the wrong type) is one line on stderr, with
the executable's own line that led to it when the mistake may be in the code, and exit 1;
Ctrl-C outside ``spin`` exits 130 quietly. Other exceptions are bugs and keep their traceback.
"""

from __future__ import annotations

import runpy
import sys
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from types import TracebackType

_ROSL = Path(__file__).resolve().parents[1]


def main(argv: list[str]) -> int:
    """Run the entry point named in ``argv`` and return its exit status."""
    from rosl.errors import RoslError

    try:
        return _run(argv)
    except RoslError as err:
        from rosl.bus.errors import BusError
        from rosl.node.errors import RosArgsError

        where = "" if isinstance(err, (RosArgsError, BusError)) else _user_line(err.__traceback__)
        message = str(err).splitlines()[0] if str(err) else type(err).__name__
        print(f"{sys.argv[0]}: {where}{message}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
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


def _run(argv: list[str]) -> int:
    package_dir, entry, name, *args = argv
    import rosl.compat

    rosl.compat.install(force=True)
    sys.path.insert(0, package_dir)
    sys.argv = [name, *args]
    if entry.endswith(".py") or "/" in entry:
        sys.path.insert(0, str(__import__("pathlib").Path(entry).parent))
        runpy.run_path(entry, run_name="__main__")
        return 0
    module_name, _, function = entry.partition(":")
    module = __import__(module_name, fromlist=["_"])
    result = getattr(module, function or "main")()
    return result if isinstance(result, int) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
