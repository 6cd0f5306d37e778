"""The parameter files a launch writes for its nodes, in its log folder (``params/``).

A node's inline parameters become a ROS 2 parameter file (``/**: ros__parameters: ...``), as
ROS 2's launch writes them; a parameter file with substitutions, its substituted copy. A dry
run (``--print``) names the files without writing them.
"""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from pathlib import Path


class ParameterFiles:
    """Writes the parameter files of one launch, numbered in the order they are written."""

    def __init__(self, log_dir: Path, *, dry_run: bool = False) -> None:
        self.folder = log_dir / "params"
        self.dry_run = dry_run
        self._numbers = itertools.count(1)

    def _path(self, label: str) -> Path:
        return self.folder / f"{label.replace('/', '_')}-{next(self._numbers)}.yaml"

    def write(self, label: str, values: dict[str, Any]) -> Path:
        """A node's parameter values as a ROS 2 parameter file; its path."""
        import yaml

        return self.write_text(label, yaml.safe_dump({"/**": {"ros__parameters": values}}))

    def write_text(self, label: str, text: str) -> Path:
        """A parameter file's text, as given; its path."""
        path = self._path(label)
        if not self.dry_run:
            self.folder.mkdir(parents=True, exist_ok=True)
            path.write_text(text, encoding="utf-8")
        return path
