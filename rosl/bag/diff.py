"""``rosl bag diff``: does a new recording match a golden one?

Topic by topic and in order: the same topics, the same number of messages on each, the same
field values — floats within an absolute tolerance, integers, booleans and strings exactly,
arrays element by element — and, when asked, the same timing (log times relative to each
bag's first compared message, within a tolerance). Equal payload bytes are equal messages;
others are decoded with this process's interface types, or with the bag's own schema when
the type is unknown here. The result lists the first differences, one readable line each.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from fnmatch import fnmatchcase
from typing import TYPE_CHECKING, Any

from rosl.bag.errors import BagError
from rosl.bag.reader import iter_bag

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.bag.reader import BagMessage

LIMIT = 20
NS = 1_000_000_000
_INDEX = re.compile(r"\[\d+\]")


@dataclass(slots=True)
class DiffResult:
    """The differences found (all counted, the first ``limit`` kept as lines)."""

    lines: list[str] = field(default_factory=list)
    count: int = 0
    messages: int = 0
    topics: int = 0
    limit: int = LIMIT

    @property
    def matched(self) -> bool:
        """Whether the bags match."""
        return self.count == 0

    def add(self, line: str) -> None:
        """Count one difference; keep its line while under the limit."""
        self.count += 1
        if len(self.lines) < self.limit:
            self.lines.append(line)

    def summary(self) -> str:
        """One line: match, or how many differences."""
        if self.matched:
            return f"bags match: {self.messages} messages on {self.topics} topics"
        shown = f" (first {len(self.lines)} shown)" if self.count > len(self.lines) else ""
        return f"bags differ: {self.count} difference(s){shown}"

    def text(self) -> str:
        """The difference lines, then the summary line."""
        return "\n".join([*self.lines, self.summary()]) + "\n"


@dataclass(frozen=True, slots=True)
class _Rules:
    tolerance: float
    ignore: tuple[str, ...]
    time_tolerance: float | None = None

    def ignored(self, path: str) -> bool:
        bare = _INDEX.sub("", path)
        return any(fnmatchcase(path, p) or fnmatchcase(bare, p) for p in self.ignore)


def compare(
    golden: Path,
    new: Path,
    *,
    topics: list[str] | None = None,
    exclude: str | None = None,
    tolerance: float = 1e-3,
    time_tolerance: float | None = None,
    ignore_fields: list[str] | tuple[str, ...] = (),
    limit: int = LIMIT,
) -> DiffResult:
    """Compare two bags' message streams topic by topic.

    Args:
        golden: the reference bag (folder or MCAP file).
        new: the bag to check.
        topics: compare only these topics (all when None).
        exclude: leave out topics matching this regular expression.
        tolerance: the largest absolute difference accepted between floats.
        time_tolerance: the largest difference (s) accepted between relative log times;
            None leaves timing unchecked.
        ignore_fields: field paths (``header.stamp``; glob patterns allowed, array indices
            optional) whose values are not compared.
        limit: how many difference lines to keep.

    Raises:
        BagError: a bag cannot be read, or ``exclude`` is not a regular expression.
    """
    try:
        pattern = re.compile(exclude) if exclude else None
    except re.error as err:
        raise BagError(f"--exclude '{exclude}' is not a regular expression: {err}") from None
    wanted = set(topics) if topics else None
    left = _streams(golden, wanted, pattern)
    right = _streams(new, wanted, pattern)
    rules = _Rules(tolerance, tuple(ignore_fields), time_tolerance)
    result = DiffResult(limit=limit)
    for name in sorted(wanted or ()):
        if name not in left and name not in right:
            result.add(f"{name}: in neither bag")
    starts = (_start(left), _start(right))
    decoders = (_Decoder(), _Decoder())
    for name in sorted(set(left) | set(right)):
        if name not in right:
            result.add(f"{name}: missing from new (golden has {len(left[name])} messages)")
        elif name not in left:
            result.add(f"{name}: only in new ({len(right[name])} messages)")
        else:
            _compare_topic(name, (left[name], right[name]), starts, decoders, rules, result)
    return result


def _compare_topic(
    name: str,
    streams: tuple[list[BagMessage], list[BagMessage]],
    starts: tuple[int, int],
    decoders: tuple[_Decoder, _Decoder],
    rules: _Rules,
    result: DiffResult,
) -> None:
    ours, theirs = streams
    result.topics += 1
    result.messages += min(len(ours), len(theirs))
    if ours[0].type != theirs[0].type:
        result.add(f"{name}: type {ours[0].type} in golden vs {theirs[0].type} in new")
        return
    if len(ours) != len(theirs):
        result.add(f"{name}: {len(ours)} messages in golden vs {len(theirs)} in new")
    for index, (a, b) in enumerate(zip(ours, theirs, strict=False)):
        where = f"{name} #{index}"
        if rules.time_tolerance is not None:
            _compare_time(where, a.log_time - starts[0], b.log_time - starts[1],
                          rules.time_tolerance, result)  # fmt: skip
        if a.data != b.data:
            _compare_payload(where, a, b, decoders, rules, result)


def _streams(
    target: Path, wanted: set[str] | None, pattern: re.Pattern[str] | None
) -> dict[str, list[BagMessage]]:
    from mcap.exceptions import McapError

    found: dict[str, list[BagMessage]] = {}
    try:
        for message in iter_bag(target, wanted):
            if pattern is None or not pattern.search(message.topic):
                found.setdefault(message.topic, []).append(message)
    except McapError as err:
        raise BagError(f"cannot read {target}: {err}") from None
    return found


def _start(streams: dict[str, list[BagMessage]]) -> int:
    return min((m[0].log_time for m in streams.values() if m), default=0)


def _compare_time(where: str, a: int, b: int, tolerance: float, result: DiffResult) -> None:
    delta = abs(a - b) / NS
    if delta > tolerance:
        result.add(
            f"{where} log time: +{a / NS:.6f} s vs +{b / NS:.6f} s "
            f"(|d|={delta:.3g} s > {tolerance:g} s)"
        )


def _compare_payload(
    where: str,
    a: BagMessage,
    b: BagMessage,
    decoders: tuple[_Decoder, _Decoder],
    rules: _Rules,
    result: DiffResult,
) -> None:
    try:
        left, right = decoders[0].decode(a), decoders[1].decode(b)
    except BagError as err:
        result.add(f"{where}: payload bytes differ and cannot be compared field by field ({err})")
        return
    _compare_value(where, "", left, right, rules, result)


def _fields(value: Any) -> list[str] | None:
    names = getattr(value, "_fields", None)
    if names is not None:
        return list(names)
    dataclass_fields = getattr(value, "__dataclass_fields__", None)
    if dataclass_fields is not None:
        return [n for n in dataclass_fields if not n.startswith("__")]
    return None


def _compare_value(
    where: str, path: str, a: Any, b: Any, rules: _Rules, result: DiffResult
) -> None:
    if path and rules.ignored(path):
        return
    names = _fields(a)
    if names is not None:
        for name in names:
            child = f"{path}.{name}" if path else name
            _compare_value(where, child, getattr(a, name), getattr(b, name, None), rules, result)
        return
    label = f"{where} {path or '(value)'}"
    if _is_sequence(a) and _is_sequence(b):
        if len(a) != len(b):
            result.add(f"{label}: length {len(a)} vs {len(b)}")
            return
        if _numeric_array(a) and _numeric_array(b):
            _compare_array(label, a, b, rules.tolerance, result)
            return
        for index, (x, y) in enumerate(zip(a, b, strict=True)):
            _compare_value(where, f"{path}[{index}]", x, y, rules, result)
        return
    if _is_float(a) or _is_float(b):
        x, y = float(a), float(b)
        if math.isnan(x) and math.isnan(y):
            return
        delta = abs(x - y)
        if not delta <= rules.tolerance:
            result.add(f"{label}: {x!r} vs {y!r} (|d|={delta:.3g} > {rules.tolerance:g})")
        return
    if _plain(a) != _plain(b):
        result.add(f"{label}: {_show(a)} vs {_show(b)}")


def _compare_array(label: str, a: Any, b: Any, tolerance: float, result: DiffResult) -> None:
    import numpy as np

    x, y = np.asarray(a), np.asarray(b)
    if x.dtype.kind == "f" or y.dtype.kind == "f":
        x, y = x.astype(float), y.astype(float)
        with np.errstate(invalid="ignore"):
            bad = ~((np.abs(x - y) <= tolerance) | (np.isnan(x) & np.isnan(y)))
    else:
        bad = x != y
    wrong = np.flatnonzero(bad)
    if wrong.size:
        first = int(wrong[0])
        more = f" (and {wrong.size - 1} more elements)" if wrong.size > 1 else ""
        result.add(f"{label}[{first}]: {_show(x[first])} vs {_show(y[first])}{more}")


def _is_sequence(value: Any) -> bool:
    return isinstance(value, (list, tuple)) or type(value).__name__ == "ndarray"


def _numeric_array(value: Any) -> bool:
    return type(value).__name__ == "ndarray" and value.dtype.kind in "biuf"


def _is_float(value: Any) -> bool:
    return isinstance(value, float) or type(value).__name__ in ("float32", "float64", "float16")


def _plain(value: Any) -> Any:
    return value.item() if hasattr(value, "item") and not isinstance(value, str) else value


def _show(value: Any) -> str:
    value = _plain(value)
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


class _Decoder:
    """Decodes one bag's payloads: the local interface types first, then the bag's schemas."""

    def __init__(self) -> None:
        self._local: dict[str, bool] = {}

    def decode(self, message: BagMessage) -> Any:
        from rosl.idl import registry
        from rosl.idl.errors import InterfaceError

        type_name = message.type
        if self._local.get(type_name, True):
            try:
                registry.get_message_class(type_name)
                return registry.store().deserialize(message.data, type_name)
            except InterfaceError:
                self._local[type_name] = False
        return self._from_schema(message)

    def _from_schema(self, message: BagMessage) -> Any:
        from rosl.idl import registry
        from rosl.idl.errors import InterfaceError

        if not message.schema_text:
            raise BagError(f"type {message.type or '(unnamed)'} is unknown and has no schema")
        try:
            return registry.store().deserialize_with_schema(
                message.data, message.type, message.schema_encoding, message.schema_text
            )
        except InterfaceError as err:
            raise BagError(str(err)) from None
