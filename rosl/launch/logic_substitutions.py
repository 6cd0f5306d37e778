"""Substitutions that compute true or false, or choose by it (launch.substitutions).

``NotSubstitution``, ``AndSubstitution``, ``OrSubstitution`` (``$(not)``, ``$(and)``,
``$(or)``), and launch's newer ``EqualsSubstitution``, ``NotEqualsSubstitution``,
``IfElseSubstitution``, ``AllSubstitution`` and ``AnySubstitution`` (``$(equals)``,
``$(not-equals)``, ``$(if)``, ``$(all)``, ``$(any)``). A boolean is ``true``/``false``, ``1``/``0``
or YAML's ``yes``/``no``/``on``/``off``, in any case.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.launch.errors import LaunchError
from rosl.launch.substitutions import SomeSubstitutions, Substitution, describe, perform

if TYPE_CHECKING:
    from rosl.launch.context import LaunchContext


def _boolean(context: LaunchContext, value: SomeSubstitutions, what: str) -> bool:
    text = perform(context, value).strip().lower()
    if text in ("true", "1", "yes", "on"):
        return True
    if text in ("false", "0", "no", "off"):
        return False
    raise LaunchError(f"{what}: '{text}' is not a boolean (true/false or 1/0)")


def _text_of(value: Any) -> SomeSubstitutions:
    """A plain value as launch's text for it (None is '', a bool 'true'/'false')."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, (Substitution, list, tuple)):
        return value
    return str(value)


class EqualsSubstitution(Substitution):
    """``'true'`` when both values are equal (``$(equals L R)``, launch since Iron).

    Booleans compare as booleans (``1`` equals ``true``), numbers as numbers (``1.0`` equals
    ``1``), anything else as text.
    """

    def __init__(self, left: Any, right: Any) -> None:
        self.left = _text_of(left)
        self.right = _text_of(right)

    def equal(self, context: LaunchContext) -> bool:
        """Whether the two sides are equal."""
        import math

        left, right = perform(context, self.left), perform(context, self.right)
        words = ("true", "false", "1", "0")
        if left.lower() in words and right.lower() in words:
            return (left.lower() in ("true", "1")) == (right.lower() in ("true", "1"))
        try:
            return math.isclose(float(left), float(right))
        except ValueError:
            return left == right

    def perform(self, context: LaunchContext) -> str:
        """``'true'`` or ``'false'``."""
        return str(self.equal(context)).lower()

    def describe(self) -> str:
        """``EqualsSubstitution(left right)``."""
        return f"{type(self).__name__}({describe(self.left)} {describe(self.right)})"


class NotEqualsSubstitution(EqualsSubstitution):
    """``'true'`` when the values differ (``$(not-equals L R)``)."""

    def perform(self, context: LaunchContext) -> str:
        """``'true'`` or ``'false'``."""
        return str(not self.equal(context)).lower()


class IfElseSubstitution(Substitution):
    """``if_value`` when the condition is true, else ``else_value`` (``$(if C A [B])``)."""

    def __init__(
        self,
        condition: SomeSubstitutions,
        if_value: SomeSubstitutions = "",
        else_value: SomeSubstitutions = "",
    ) -> None:
        if if_value == else_value == "":
            raise LaunchError("IfElseSubstitution: give if_value, else_value or both")
        self.condition = condition
        self.if_value = if_value
        self.else_value = else_value

    def perform(self, context: LaunchContext) -> str:
        """One of the two values."""
        chosen = self.if_value if _boolean(context, self.condition, "if") else self.else_value
        return perform(context, chosen)

    def describe(self) -> str:
        """``IfElseSubstitution(condition, if, else)``."""
        parts = (self.condition, self.if_value, self.else_value)
        return f"IfElseSubstitution({', '.join(describe(p) for p in parts)})"


class AllSubstitution(Substitution):
    """``'true'`` when every value is true (``$(all A B ...)``)."""

    word = "all"

    def __init__(self, *args: SomeSubstitutions) -> None:
        self.args = list(args)

    def perform(self, context: LaunchContext) -> str:
        """``'true'`` or ``'false'``."""
        values = [_boolean(context, a, self.word) for a in self.args]
        return str(all(values) if self.word == "all" else any(values)).lower()

    def describe(self) -> str:
        """``AllSubstitution(a b ...)``."""
        return f"{type(self).__name__}({' '.join(describe(a) for a in self.args)})"


class AnySubstitution(AllSubstitution):
    """``'true'`` when any value is true (``$(any A B ...)``)."""

    word = "any"


class NotSubstitution(Substitution):
    """``'true'`` when the value is false (``$(not V)``)."""

    def __init__(self, value: SomeSubstitutions) -> None:
        self.value = value

    def perform(self, context: LaunchContext) -> str:
        """``'true'`` or ``'false'``."""
        return str(not _boolean(context, self.value, "not")).lower()

    def describe(self) -> str:
        """``NotSubstitution(...)``."""
        return f"NotSubstitution({describe(self.value)})"


class AndSubstitution(Substitution):
    """``'true'`` when both values are true (``$(and L R)``)."""

    word = "and"

    def __init__(self, left: SomeSubstitutions, right: SomeSubstitutions) -> None:
        self.left = left
        self.right = right

    def combine(self, left: bool, right: bool) -> bool:
        """The logical operation."""
        return left and right

    def perform(self, context: LaunchContext) -> str:
        """``'true'`` or ``'false'``."""
        left = _boolean(context, self.left, self.word)
        right = _boolean(context, self.right, self.word)
        return str(self.combine(left, right)).lower()

    def describe(self) -> str:
        """``AndSubstitution(left right)``."""
        return f"{type(self).__name__}({describe(self.left)} {describe(self.right)})"


class OrSubstitution(AndSubstitution):
    """``'true'`` when either value is true (``$(or L R)``)."""

    word = "or"

    def combine(self, left: bool, right: bool) -> bool:
        """The logical operation."""
        return left or right
