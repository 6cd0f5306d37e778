"""YAML with line numbers, and the checks world and robot files share (keys, numbers, points).

Each mapping remembers its own line and the line of each key, and each list the line of each
item, so every complaint can say ``file:line: what is expected``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Literal, overload

import yaml

from rosl.sim.errors import WorldFileError

if TYPE_CHECKING:
    from collections.abc import Hashable
    from pathlib import Path

LINES = "__lines__"
LINE = "__line__"

Point = tuple[float, float]


class Loader(yaml.SafeLoader):
    """Remembers the line of every mapping and of each of its keys, and of each list item."""


class Items(list[Any]):
    """A YAML list that remembers the line of each of its items."""

    lines: list[int]


def _mapping(loader: Loader, node: yaml.MappingNode) -> dict[Hashable, Any]:
    mapping = loader.construct_mapping(node, deep=True)
    mapping[LINE] = node.start_mark.line + 1
    mapping[LINES] = {k.value: k.start_mark.line + 1 for k, _ in node.value}
    return mapping


def _sequence(loader: Loader, node: yaml.SequenceNode) -> Items:
    items = Items(loader.construct_sequence(node, deep=True))
    items.lines = [item.start_mark.line + 1 for item in node.value]
    return items


Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping)
Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_SEQUENCE_TAG, _sequence)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


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
        except (OSError, UnicodeDecodeError) as err:
            reason = err.strerror if isinstance(err, OSError) else "not UTF-8 text"
            raise WorldFileError(f"{self.path}: cannot read: {reason}") from None
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

                hint = did_you_mean(str(key), allowed)
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

    def mapping(self, entry: dict[str, Any], key: str, what: str) -> dict[str, Any]:
        """The mapping under ``key`` (an empty one, at the key's line, when absent or empty)."""
        value = entry.get(key)
        line = self.line_of(entry, key)
        if value is None:
            return {LINE: line, LINES: {}}
        if not isinstance(value, dict):
            raise self.fail(line, f"'{key}' must be a mapping ({what}), not {_show(value)}")
        return value

    def sequence(self, entry: dict[str, Any], key: str, what: str) -> list[tuple[int, Any]]:
        """(line, item) for each item of the list under ``key`` (none when absent or empty)."""
        value = entry.get(key)
        line = self.line_of(entry, key)
        if value is None:
            return []
        if not isinstance(value, list):
            raise self.fail(line, f"'{key}' must be a list of {what}, not {_show(value)}")
        lines = getattr(value, "lines", [line] * len(value))
        return list(zip(lines, value, strict=True))

    def item(self, line: int, value: Any, what: str) -> dict[str, Any]:
        """A list item that must be a mapping."""
        if not isinstance(value, dict):
            raise self.fail(line, f"each entry here must be a mapping ({what}), not {_show(value)}")
        return value

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
        line = self.line_of(entry, key)
        if not _is_number(value):
            raise self.fail(line, f"'{key}' must be a number, not {_show(value)}")
        if positive and value <= 0:
            raise self.fail(line, f"'{key}' must be greater than 0, not {value}")
        if minimum is not None and value < minimum:
            raise self.fail(line, f"'{key}' must be at least {minimum}, not {value}")
        return float(value)

    def integer(
        self, entry: dict[str, Any], key: str, *, default: int | None = None, minimum: int = 0
    ) -> int:
        """A whole number of at least ``minimum``, or the default."""
        if key not in entry and default is not None:
            return default
        value = entry.get(key)
        if not isinstance(value, int) or isinstance(value, bool) or value < minimum:
            raise self.fail(
                self.line_of(entry, key),
                f"'{key}' must be a whole number of at least {minimum}, not {_show(value)}",
            )
        return value

    def flag(self, entry: dict[str, Any], key: str, default: bool = False) -> bool:
        """A true/false value."""
        value = entry.get(key, default)
        if not isinstance(value, bool):
            raise self.fail(
                self.line_of(entry, key), f"'{key}' must be true or false, not {_show(value)}"
            )
        return value

    @overload
    def point(
        self, entry: dict[str, Any], key: str, size: Literal[2] = 2
    ) -> tuple[float, float]: ...
    @overload
    def point(
        self, entry: dict[str, Any], key: str, size: Literal[3]
    ) -> tuple[float, float, float]: ...
    def point(self, entry: dict[str, Any], key: str, size: int = 2) -> tuple[float, ...]:
        """A list of ``size`` finite numbers: ``[x, y]`` or ``[x, y, yaw]``."""
        value = entry.get(key)
        if not isinstance(value, list) or len(value) != size or not all(map(_is_number, value)):
            shape = "[x, y]" if size == 2 else "[x, y, yaw]" if size == 3 else f"{size} numbers"
            raise self.fail(
                self.line_of(entry, key), f"'{key}' must be {shape} (finite numbers), "
                f"not {_show(value)}",
            )  # fmt: skip
        return tuple(float(v) for v in value)

    def text(self, entry: dict[str, Any], key: str, default: str | None = None) -> str:
        """A string value."""
        value = entry.get(key, default)
        if not isinstance(value, str):
            raise self.fail(self.line_of(entry, key), f"'{key}' must be text, not {_show(value)}")
        return value

    def texts(self, entry: dict[str, Any], key: str) -> tuple[str, ...]:
        """A list of strings (empty when absent)."""
        out = []
        for line, value in self.sequence(entry, key, "names"):
            if not isinstance(value, str):
                raise self.fail(line, f"each of '{key}' must be text, not {_show(value)}")
            out.append(value)
        return tuple(out)

    def points(self, entry: dict[str, Any], key: str, minimum: int) -> list[Point]:
        """A list of at least ``minimum`` ``[x, y]`` points."""
        items = self.sequence(entry, key, "[x, y] points")
        if len(items) < minimum:
            raise self.fail(
                self.line_of(entry, key),
                f"'{key}' must be a list of at least {minimum} [x, y] points",
            )
        out = []
        for line, item in items:
            if not isinstance(item, list) or len(item) != 2 or not all(map(_is_number, item)):
                raise self.fail(line, f"each of '{key}' must be [x, y], not {_show(item)}")
            out.append((float(item[0]), float(item[1])))
        return out


def _show(value: Any) -> str:
    """A value as the user wrote it, without the line bookkeeping."""
    return repr(_plain(value))


def _plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items() if k not in (LINE, LINES)}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value
