"""Put the top-level interfaces/, worlds/ and examples/ into the wheel as rosl/_data/.

rosl/resources.py finds them there, or in the checkout for an editable install.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

_SHIPPED = ("interfaces", "worlds", "examples")


class _BuildPyWithData(build_py):
    """build_py that also places the shipped data folders inside the rosl package."""

    def run(self) -> None:
        super().run()
        if self.editable_mode:  # an editable install reads them from the checkout
            return
        root = Path(__file__).resolve().parent
        for name in _SHIPPED:
            if not (root / name).is_dir():
                continue  # e.g. a fresh clone where git kept no empty folder
            target = Path(self.build_lib) / "rosl" / "_data" / name
            if target.exists():
                shutil.rmtree(target)
            shutil.copytree(root / name, target, ignore=shutil.ignore_patterns("__pycache__"))


setup(cmdclass={"build_py": _BuildPyWithData})
