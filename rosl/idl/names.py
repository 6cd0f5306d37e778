"""Interface type names: one canonical spelling inside rosl, lenient spellings at the edges.

Canonical names are ``pkg/msg/Name``, ``pkg/srv/Name`` and, for the two halves of a service,
``pkg/srv/Name_Request`` / ``pkg/srv/Name_Response``. An action ``pkg/action/Name`` has the
types rosidl generates for it: ``Name_Goal``, ``Name_Result``, ``Name_Feedback``,
``Name_FeedbackMessage`` and the services ``Name_SendGoal`` / ``Name_GetResult`` (with their
``_Request`` / ``_Response``). Users may also write ``pkg/Name`` (a message, or a service where a
service is expected) and ``pkg.msg.Name``.
"""

from __future__ import annotations

import difflib
import re
from typing import TYPE_CHECKING, NamedTuple

from rosl.idl.errors import InterfaceError

if TYPE_CHECKING:
    from collections.abc import Iterable

PACKAGE_NAME = re.compile(r"^(?!.*__)(?!.*_$)[a-z][a-z0-9_]*$")
FIELD_NAME = PACKAGE_NAME
TYPE_NAME = re.compile(r"^[A-Z][A-Za-z0-9]*$")
CONSTANT_NAME = re.compile(r"^[A-Z]([A-Z0-9_]?[A-Z0-9]+)*$")
KINDS = ("msg", "srv", "action")
SERVICE_SUFFIXES = ("_Request", "_Response", "_Event")
# longest first: the first that matches is cut off
ACTION_SUFFIXES = (
    "_SendGoal_Request", "_SendGoal_Response", "_GetResult_Request", "_GetResult_Response",
    "_FeedbackMessage", "_SendGoal", "_GetResult", "_Feedback", "_Result", "_Goal",
)  # fmt: skip


class TypeName(NamedTuple):
    """A parsed canonical type name."""

    package: str
    kind: str
    name: str

    def __str__(self) -> str:
        return f"{self.package}/{self.kind}/{self.name}"

    @property
    def python_name(self) -> str:
        """The dotted spelling rclpy prints, e.g. ``geometry_msgs.msg.Twist``."""
        return f"{self.package}.{self.kind}.{self.name}"


def parse_type_name(text: str, default_kind: str = "msg") -> TypeName:
    """Parse a user-written type name into its canonical parts.

    Args:
        text: ``pkg/msg/Name``, ``pkg/srv/Name``, ``pkg/Name`` or ``pkg.msg.Name``.
        default_kind: the kind assumed for the two-part form ``pkg/Name``.

    Returns:
        The canonical name.

    Raises:
        InterfaceError: the text is not a valid type name.
    """
    parts = text.strip().replace(".", "/").split("/")
    if len(parts) == 2:
        parts = [parts[0], default_kind, parts[1]]
    if len(parts) != 3 or not all(parts):
        raise InterfaceError(
            f"invalid type name '{text}': expected 'pkg/msg/Name', 'pkg/srv/Name' or 'pkg/Name'"
        )
    package, kind, name = parts
    if kind not in KINDS:
        raise InterfaceError(
            f"invalid type name '{text}': the middle part must be one of {', '.join(KINDS)}"
        )
    if not PACKAGE_NAME.match(package):
        raise InterfaceError(f"invalid type name '{text}': '{package}' is not a package name")
    base = base_name(name, kind)
    if not TYPE_NAME.match(base):
        raise InterfaceError(
            f"invalid type name '{text}': '{name}' must start with a capital letter "
            "and hold only letters and digits"
        )
    return TypeName(package, kind, name)


def base_name(name: str, kind: str) -> str:
    """The interface a type belongs to: ``Fibonacci`` for ``Fibonacci_SendGoal_Request``."""
    suffixes = SERVICE_SUFFIXES if kind == "srv" else ACTION_SUFFIXES if kind == "action" else ()
    for suffix in suffixes:
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return name


def canonical(text: str, default_kind: str = "msg") -> str:
    """Return the canonical spelling of a user-written type name."""
    return str(parse_type_name(text, default_kind))


def closest(word: str, candidates: Iterable[str], n: int = 3) -> list[str]:
    """Return up to ``n`` candidates close to ``word``, closest first."""
    return difflib.get_close_matches(word, sorted(candidates), n=n, cutoff=0.6)


def did_you_mean(word: str, candidates: Iterable[str]) -> str:
    """Return `` (did you mean 'x'?)`` for the closest candidate, or an empty string."""
    found = closest(word, candidates, n=2)
    if not found:
        return ""
    return " (did you mean " + " or ".join(f"'{c}'" for c in found) + "?)"
