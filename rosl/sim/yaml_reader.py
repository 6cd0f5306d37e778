"""YAML with line numbers, and the checks world and robot files share (keys, numbers, points).

Each mapping remembers its own line and the line of each key, so every complaint can say
``file:line: what is expected``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import yaml

from rosl.sim.errors import WorldFileError

if TYPE_CHECKING:
    from pathlib import Path

LINES = "__lines__"
LINE = "__line__"

Point = tuple[float, float]


class Loader(yaml.SafeLoader):
    """Remembers the line of every mapping and of each of its keys."""


def _mapping(loader: Loader, node: yaml.MappingNode) -> dict[str, Any]:
    mapping = loader.construct_mapping(node, deep=True)
    mapping[LINE] = node.start_mark.line + 1
    mapping[LINES] = {k.value: k.start_mark.line + 1 for k, _ in node.value}
    return mapping


Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping)


class YamlReader:
    """Loads one YAML file and checks its entries, failing with file:line."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, line: int, message: str) -> WorldFileError:
        """The error for ``line``: ``file:line: message``."""
        return WorldFileError(f"{self.path}:{line}: {message}")

    def load(self) -> dict[str, Any]:
        """The file's top-level mapping (every mapping carries its lines)."""
        try:
            data = yaml.load(self.path.read_text(encoding="utf-8"), Loader=Loader)
        except yaml.YAMLError as err:
            mark = getattr(err, "problem_mark", None)
            line = mark.line + 1 if mark is not None else 0
            raise WorldFileError(
                f"{self.path}:{line}: not valid YAML: {getattr(err, 'problem', err)}"
            ) from None
        except OSError as err:
            raise WorldFileError(f"{self.path}: cannot read: {err.strerror}") from None
        if not isinstance(data, dict):
            raise self.fail(1, "expected a mapping with 'format:' at the top")
        return data

    def keys(self, entry: dict[str, Any], allowed: set[str], required: set[str], what: str) -> None:
        """Refuse unknown keys (with a did-you-mean) and missing required ones."""
        line = entry.get(LINE, 0)
        for key in entry:
            if key in (LINE, LINES):
                continue
            if key not in allowed:
                from rosl.idl.names import did_you_mean

                hint = did_you_mean(key, allowed)
                raise self.fail(
                    self.line_of(entry, key),
                    f"unknown key '{key}' in {what}{hint} (expected: {', '.join(sorted(allowed))})",
                )
        for key in sorted(required):
            if key not in entry:
                raise self.fail(line, f"{what} needs '{key}:'")

    @staticmethod
    def line_of(entry: dict[str, Any], key: str) -> int:
        """The line of ``key`` in ``entry`` (or of the entry itself)."""
        return int(entry.get(LINES, {}).get(key, entry.get(LINE, 0)))

    def number(
        self,
        entry: dict[str, Any],
        key: str,
        *,
        default: float | None = None,
        positive: bool = False,
        minimum: float | None = None,
    ) -> float:
        """A finite number (optionally > 0 or >= ``minimum``), or the default."""
        if key not in entry:
            if default is None:
                raise self.fail(entry.get(LINE, 0), f"missing '{key}:' (a number)")
            return default
        value = entry[key]
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
        ):
            raise self.fail(self.line_of(entry, key), f"'{key}' must be a number, not {value!r}")
        if positive and value <= 0:
            raise self.fail(
                self.line_of(entry, key), f"'{key}' must be greater than 0, not {value}"
            )
        if minimum is not None and value < minimum:
            raise self.fail(
                self.line_of(entry, key), f"'{key}' must be at least {minimum}, not {value}"
            )
        return float(value)

    def point(self, entry: dict[str, Any], key: str, size: int = 2) -> tuple[float, ...]:
        """A list of ``size`` numbers: ``[x, y]`` or ``[x, y, yaw]``."""
        value = entry.get(key)
        if (
            not isinstance(value, list)
            or len(value) != size
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        ):
            shape = "[x, y]" if size == 2 else "[x, y, yaw]" if size == 3 else f"{size} numbers"
            raise self.fail(self.line_of(entry, key), f"'{key}' must be {shape}, not {value!r}")
        return tuple(float(v) for v in value)

    def text(self, entry: dict[str, Any], key: str, default: str | None = None) -> str:
        """A string value."""
        value = entry.get(key, default)
        if not isinstance(value, str):
            raise self.fail(self.line_of(entry, key), f"'{key}' must be text, not {value!r}")
        return value

    def points(self, entry: dict[str, Any], key: str, minimum: int) -> list[Point]:
        """A list of at least ``minimum`` ``[x, y]`` points."""
        value = entry.get(key)
        line = self.line_of(entry, key)
        if not isinstance(value, list) or len(value) < minimum:
            raise self.fail(line, f"'{key}' must be a list of at least {minimum} [x, y] points")
        out = []
        for item in value:
            if (
                not isinstance(item, list)
                or len(item) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in item)
            ):
                raise self.fail(line, f"each of '{key}' must be [x, y], not {item!r}")
            out.append((float(item[0]), float(item[1])))
        return out


# --- shapes ---------------------------------------------------------------------------------
