"""Run one executable of a package: ``python -m rosl.pkg.entry PKG_DIR ENTRY NAME [args...]``.

ENTRY is ``module:function`` (imported with the package folder on ``sys.path``) or a Python
file. rosl's import hooks are installed first, so ``import rclpy`` and
``from std_msgs.msg import String`` work in the executable unchanged.
"""

from __future__ import annotations

import runpy
import sys


def main(argv: list[str]) -> int:
    """Run the entry point named in ``argv`` and return its exit status."""
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
