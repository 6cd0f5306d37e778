"""The ``$(...)`` strings of XML and YAML launch files: their grammar and their substitutions.

``parse_substitution`` reads a string as launch's frontend grammar does (``$(name args...)``,
nested, quoted, backslash escapes) into the substitutions a Python launch file would build
(:mod:`rosl.launch.substitutions`); ``SUBSTITUTIONS`` names what ``$(name ...)`` may say.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

from rosl.launch import logic_substitutions as logic
from rosl.launch import substitutions as subs

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

# ---------------------------------------------------------------------------

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")


class SubstitutionSyntaxError(ValueError):
    """A ``$(...)`` string that cannot be read (the caller adds file and line)."""


def joined(parts: list[Any]) -> Any:
    """Merge adjacent text; a lone text stays a ``str``, several parts a list (tuple-free)."""
    merged: list[Any] = []
    for part in parts:
        if isinstance(part, str) and merged and isinstance(merged[-1], str):
            merged[-1] += part
        elif part != "":
            merged.append(part)
    if not merged:
        return ""
    return merged[0] if len(merged) == 1 and isinstance(merged[0], str) else merged


class _Scanner:
    r"""``$(name arg ...)`` as launch's grammar reads it.

    Arguments are split by spaces and may be quoted with '...' or "..." (substitutions nest in
    both); ``\x`` is ``x``.
    """

    def __init__(self, text: str, path: Path | None) -> None:
        self.text = text
        self.pos = 0
        self.path = path

    def read(self, stops: str, quote: str | None, refused: str = "") -> Any:
        """Text and substitutions up to a character of ``stops`` (or the end)."""
        parts: list[Any] = []
        text = self.text
        while self.pos < len(text):
            char = text[self.pos]
            if char == "\\" and self.pos + 1 < len(text):
                parts.append(text[self.pos + 1])
                self.pos += 2
            elif text.startswith("$(", self.pos):
                parts.append(self.substitution(quote))
            elif char in stops:
                break
            elif char in refused:
                raise SubstitutionSyntaxError(
                    f"{char!r} at column {self.pos + 1} inside an argument: quote the whole "
                    "argument ('...' or \"...\") or escape it with \\"
                )
            else:
                parts.append(char)
                self.pos += 1
        return joined(parts)

    def substitution(self, quote: str | None) -> subs.Substitution:
        start = self.pos
        match = _NAME.match(self.text, self.pos + 2)
        if match is None:
            raise SubstitutionSyntaxError(
                f"a substitution name must follow '$(' at column {start + 1}"
            )
        name = match.group()
        self.pos = match.end()
        arguments: list[Any] = []
        while self.pos < len(self.text) and self.text[self.pos] != ")":
            if self.text[self.pos] != " ":
                break
            while self.text.startswith(" ", self.pos):
                self.pos += 1
            if self.text.startswith(")", self.pos) or self.pos >= len(self.text):
                continue
            if quote is None and self.text[self.pos] in "'\"":
                arguments.append(self.quoted(self.text[self.pos]))
            else:  # inside quotes, a nested argument is unquoted (launch's grammar)
                arguments.append(
                    self.read(" )" + (quote or ""), quote, "(" + ("'\"" if quote is None else ""))
                )
        if self.pos >= len(self.text) or self.text[self.pos] == quote:
            raise SubstitutionSyntaxError(
                f"'$({name}' at column {start + 1} is not closed with ')'"
            )
        if self.text[self.pos] != ")":
            raise SubstitutionSyntaxError(
                f"unexpected {self.text[self.pos]!r} at column {self.pos + 1} in '$({name} ...)'"
            )
        self.pos += 1
        return instantiate(name, arguments, self.path)

    def quoted(self, quote: str) -> Any:
        start = self.pos
        self.pos += 1
        value = self.read(quote, quote)
        if self.pos >= len(self.text):
            raise SubstitutionSyntaxError(f"the quote {quote} at column {start + 1} is not closed")
        self.pos += 1
        if self.pos < len(self.text) and self.text[self.pos] not in " )":
            raise SubstitutionSyntaxError(
                f"a space or ')' must follow the quoted argument at column {start + 1}"
            )
        return value


def parse_substitution(text: str, *, path: Path | None = None) -> Any:
    """``'a $(var x) b'`` as ``['a ', LaunchConfiguration('x'), ' b']`` (plain text as ``str``).

    Args:
        text: the attribute's text.
        path: the launch file it comes from (``$(dirname)``, ``$(filename)``).

    Raises:
        SubstitutionSyntaxError: bad syntax, an unknown substitution, wrong arguments.
    """
    return _Scanner(text, path).read("", None)


def _literal(value: Any, what: str) -> str:
    if not isinstance(value, str):
        raise SubstitutionSyntaxError(f"the {what} must be plain text, not a substitution")
    return value


def _env(arguments: list[Any], path: Path | None) -> subs.Substitution:
    default = arguments[1] if len(arguments) > 1 else None
    return subs.EnvironmentVariable(arguments[0], default_value=default)


def _optenv(arguments: list[Any], path: Path | None) -> subs.Substitution:
    default: list[Any] = []
    for index, word in enumerate(arguments[1:]):  # ROS 1: the default may be several words
        default += [" ", word] if index else [word]
    return subs.EnvironmentVariable(arguments[0], default_value=joined(default))


def _eval(arguments: list[Any], path: Path | None) -> subs.Substitution:
    if len(arguments) == 1:
        return subs.PythonExpression(arguments[0])
    modules = _literal(arguments[1], "module list of $(eval)").split(",")
    return subs.PythonExpression(arguments[0], [m.strip() for m in modules if m.strip()])


def _command(arguments: list[Any], path: Path | None) -> subs.Substitution:
    if len(arguments) == 1:
        return subs.Command(arguments[0])
    return subs.Command(arguments[0], on_stderr=arguments[1])


def _loops() -> Any:
    from rosl.launch import loops

    return loops


_Factory = tuple[int, int, "Callable[[list[Any], Path | None], subs.Substitution]"]
SUBSTITUTIONS: dict[str, _Factory] = {
    "var": (1, 2, lambda a, p: subs.LaunchConfiguration(a[0], default=a[1] if a[1:] else None)),
    "env": (1, 2, _env),
    "optenv": (1, 1 << 10, _optenv),
    "find-pkg-share": (1, 1, lambda a, p: subs.FindPackageShare(a[0])),
    "find-pkg-prefix": (1, 1, lambda a, p: subs.FindPackagePrefix(a[0])),
    "find-package": (1, 1, lambda a, p: subs.FindPackage(a[0])),
    "find-exec": (1, 1, lambda a, p: subs.FindExecutable(name=a[0])),
    "exec-in-package": (2, 2, lambda a, p: subs.ExecutableInPackage(a[0], a[1])),
    "exec-in-pkg": (2, 2, lambda a, p: subs.ExecutableInPackage(a[0], a[1])),
    "eval": (1, 2, _eval),
    "command": (1, 2, _command),
    "anon": (1, 1, lambda a, p: subs.AnonName(a[0])),
    "dirname": (0, 0, lambda a, p: subs.ThisLaunchFileDir(path=p)),
    "filename": (0, 0, lambda a, p: subs.ThisLaunchFile(path=p)),
    "not": (1, 1, lambda a, p: logic.NotSubstitution(a[0])),
    "and": (2, 2, lambda a, p: logic.AndSubstitution(a[0], a[1])),
    "or": (2, 2, lambda a, p: logic.OrSubstitution(a[0], a[1])),
    "index": (1, 1, lambda a, p: _loops().ForLoopIndex(a[0])),
    "for-var": (
        1,
        2,
        lambda a, p: _loops().ForEachVar(a[0], default_value=a[1] if a[1:] else None),
    ),
    "file-content": (1, 1, lambda a, p: subs.FileContent(a[0])),
    "launch-log-dir": (0, 0, lambda a, p: subs.LaunchLogDir()),
    "equals": (2, 2, lambda a, p: logic.EqualsSubstitution(a[0], a[1])),
    "not-equals": (2, 2, lambda a, p: logic.NotEqualsSubstitution(a[0], a[1])),
    "if": (2, 3, lambda a, p: logic.IfElseSubstitution(*a)),
    "all": (1, 1 << 10, lambda a, p: logic.AllSubstitution(*a)),
    "any": (1, 1 << 10, lambda a, p: logic.AnySubstitution(*a)),
}


def instantiate(name: str, arguments: list[Any], path: Path | None) -> subs.Substitution:
    """The substitution ``$(name arguments...)``.

    Raises:
        SubstitutionSyntaxError: an unknown name or the wrong number of arguments.
    """
    from rosl.idl.names import did_you_mean

    if name not in SUBSTITUTIONS:
        raise SubstitutionSyntaxError(
            f"unknown substitution '$({name})'{did_you_mean(name, SUBSTITUTIONS)}; rosl reads: "
            + ", ".join(SUBSTITUTIONS)
        )
    least, most, factory = SUBSTITUTIONS[name]
    if not least <= len(arguments) <= most:
        wanted = str(least) if least == most else f"{least} to {most}"
        if most >= 1 << 10:
            wanted = f"at least {least}"
        raise SubstitutionSyntaxError(f"$({name}) takes {wanted} argument(s), not {len(arguments)}")
    return factory(arguments, path)
