"""launch_testing.tools: matching a command's output, filtering it, and running a process.

``expect_output(text, expected_lines=[...], strict=True)`` says whether output holds the
expected lines (strings are found inside a line, compiled patterns must match it) or text, in
order; with ``strict`` nothing else may come between them. ``basic_output_filter`` drops lines
by prefix or pattern; ``launch_process`` (in :mod:`rosl.launch.testing.process_proxy`) starts a
process from an active test and hands back a ``ProcessProxy`` to wait on it.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Callable

_ANSI = re.compile(r"\x1b\[[0-9;?]*[ -/]*[@-~]")

Span = tuple[int, int] | None


def remove_ansi_escape_sequences(text: str) -> str:
    """The text without terminal colour and cursor sequences."""
    return _ANSI.sub("", text)


def normalize_lineseps(text: str) -> str:
    r"""The text with every line ending as ``\n`` (an emulated tty writes ``\r\n``)."""
    return text.replace(os.linesep, "\n").replace("\r\n", "\n")


def _is_pattern(value: Any) -> bool:
    return hasattr(value, "match") and hasattr(value, "search")


def build_line_match(expected_lines: Any, *, strict: bool = False) -> Callable[..., Span]:
    """A matcher of a list of lines against an expectation (a text, a pattern, or a list).

    The matcher takes ``(lines, start=0)`` and returns the ``(first, end)`` line span matched,
    or None. A text is found inside a line, a pattern must match at the line's start.

    Raises:
        ValueError: the expectation is none of those.
    """
    if isinstance(expected_lines, str) or _is_pattern(expected_lines):
        one = expected_lines

        def hit(line: str) -> bool:
            return (one in line) if isinstance(one, str) else bool(one.match(line))

        def single(lines: list[str], start: int = 0) -> Span:
            if strict:
                rest = lines[start:]
                return (start, len(lines)) if all(hit(line) for line in rest) else None
            return next(((i, i + 1) for i in range(start, len(lines)) if hit(lines[i])), None)

        return single
    if isinstance(expected_lines, Iterable):
        parts = [build_line_match(item) for item in expected_lines]
        return _sequence(parts, strict)
    raise ValueError(f"unknown format for expected lines: {expected_lines!r}")


def build_text_match(expected_text: Any, *, strict: bool = False) -> Callable[..., Span]:
    """A matcher of a text against an expectation (a text, a pattern, or a list of them).

    The matcher takes ``(text, start=0)`` and returns the ``(start, end)`` span matched, or None.

    Raises:
        ValueError: the expectation is none of those.
    """
    if isinstance(expected_text, str):
        wanted = expected_text

        def literal(text: str, start: int = 0) -> Span:
            text = normalize_lineseps(text)
            if strict:
                return (start, start + len(wanted)) if text[start:] == wanted else None
            found = text.find(wanted, start)
            return None if found < 0 else (found, found + len(wanted))

        return literal
    if _is_pattern(expected_text):
        pattern = expected_text

        def regex(text: str, start: int = 0) -> Span:
            text = normalize_lineseps(text)
            found = pattern.match(text, start) if strict else pattern.search(text, start)
            return None if found is None else (found.start(), found.end())

        return regex
    if isinstance(expected_text, Iterable):
        return _sequence([build_text_match(item) for item in expected_text], strict)
    raise ValueError(f"unknown format for expected text: {expected_text!r}")


def _sequence(parts: list[Callable[..., Span]], strict: bool) -> Callable[..., Span]:
    """Each part after the previous one (right after it, with ``strict``)."""

    def match(actual: Any, start: int = 0) -> Span:
        if not parts:
            return (start, start)
        first = parts[0](actual, start)
        if first is None or (strict and first[0] != start):
            return None
        begin, end = first
        for part in parts[1:]:
            span = part(actual, end)
            if span is None or (strict and span[0] != end):
                return None
            end = span[1]
        return begin, end

    return match


def expect_output(
    text: str | None = None,
    *,
    lines: list[str] | None = None,
    expected_text: Any = None,
    expected_lines: Any = None,
    strip_ansi_escape_sequences: bool = True,
    strict: bool = False,
) -> bool:
    r"""Whether output (``text`` or ``lines``) holds the expected text or lines.

    Lines given where text is expected are joined with ``\n``; text given where lines are
    expected is split into lines.

    Raises:
        ValueError: not exactly one of text/lines, or of expected_text/expected_lines.
    """
    if (text is None) == (lines is None):
        raise ValueError("Either lines or text, but not both, must be specified")
    if (expected_text is None) == (expected_lines is None):
        raise ValueError("Either expected lines or text, but not both, must be specified")
    clean = remove_ansi_escape_sequences if strip_ansi_escape_sequences else str
    if expected_text is not None:
        whole = text if text is not None else "\n".join(lines or [])
        return build_text_match(expected_text, strict=strict)(clean(whole)) is not None
    found = lines if lines is not None else (text or "").splitlines()
    return build_line_match(expected_lines, strict=strict)([clean(x) for x in found]) is not None


def get_default_filtered_prefixes() -> list[str]:
    """Lines starting with these are dropped by default (``pid``, ``rc``)."""
    return ["pid", "rc"]


def get_default_filtered_patterns() -> list[str]:
    """Lines matching these are dropped by default (none)."""
    return []


def basic_output_filter(
    filtered_prefixes: list[str] | None = None,
    filtered_patterns: list[str] | None = None,
    filtered_rmw_implementation: str | None = None,
) -> Callable[[str], str]:
    """A function dropping the output lines that start with a prefix or match a pattern.

    ``filtered_rmw_implementation`` (launch_testing_ros's argument) adds nothing: rosl's
    transport prints no lines of its own.
    """
    prefixes = get_default_filtered_prefixes() if filtered_prefixes is None else filtered_prefixes
    patterns = [
        re.compile(p)
        for p in (
            get_default_filtered_patterns() if filtered_patterns is None else filtered_patterns
        )
    ]
    del filtered_rmw_implementation

    def output_filter(output: str) -> str:
        kept = [
            line
            for line in output.splitlines(keepends=True)
            if not any(line.startswith(p) for p in prefixes)
            and not any(p.match(line) for p in patterns)
        ]
        return "".join(kept)

    return output_filter


def expected_output_from_file(path: str, encoding: str | None = None) -> list[Any]:
    """The expected lines in ``path.txt`` (literal) or ``path.regex`` (one pattern a line).

    Raises:
        RuntimeError: neither file exists.
    """
    if os.path.isfile(path + ".txt"):
        with open(path + ".txt", encoding=encoding) as f:
            return f.read().splitlines()
    if os.path.isfile(path + ".regex"):
        with open(path + ".regex", encoding=encoding) as f:
            return [re.compile(line) for line in f.read().splitlines()]
    raise RuntimeError(f"could not find output check file: {path} (.txt or .regex)")
