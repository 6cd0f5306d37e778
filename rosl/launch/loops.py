"""Loops in launch files (launch's ForLoop and ForEach, newest distros): N copies of actions.

``ForLoop(LaunchConfiguration('num'), function=for_i)`` calls ``for_i(i=0..N-1)`` and runs the
actions it returns; ``ForEach("{name: a, id: 1};{name: b, id: 2}", function=f)`` calls ``f``
with each YAML mapping's keys as keyword arguments. In XML and YAML the children of
``<for len= name=>`` / ``<for_each values=>`` are built once per iteration, and read the
iteration's values with ``$(index NAME)`` / ``$(for-var NAME [DEFAULT])``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.launch.description import Action, process
from rosl.launch.errors import LaunchError
from rosl.launch.substitutions import SomeSubstitutions, Substitution, describe, perform

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.launch.context import LaunchContext

SEPARATOR = ";"
_LOCALS = "for_vars"  # context.locals key: the values of the iterations being processed


class ForEach(Action):
    """Call ``function(**values)`` for each ';'-separated YAML mapping; run what it returns."""

    def __init__(
        self,
        input_values: SomeSubstitutions,
        *,
        function: Callable[..., list[Any] | None],
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.input_values = input_values
        self.function = function

    def iterations(self, context: LaunchContext) -> list[dict[str, Any]]:
        """The value sets, each a mapping.

        Raises:
            LaunchError: a set that is not a YAML mapping.
        """
        import yaml

        text = perform(context, self.input_values)
        found: list[dict[str, Any]] = []
        for part in (p.strip() for p in text.strip().split(SEPARATOR)):
            if not part:
                continue
            try:
                values = yaml.safe_load(part)
            except yaml.YAMLError:
                values = part
            if values is None:
                values = {}
            if not isinstance(values, dict):
                raise LaunchError(
                    f"for_each: '{part}' is not a YAML mapping such as {{name: a, id: 1}}"
                )
            found.append({str(k): v for k, v in values.items()})
        return found

    def execute(self, context: LaunchContext) -> list[Any] | None:
        """The entities of every iteration, in order."""
        entities: list[Any] = []
        for values in self.iterations(context):
            entities += list(self.function(**values) or [])
        return entities


class ForLoop(Action):
    """Call ``function(i=...)`` for i in 0..length-1; run what it returns."""

    def __init__(
        self,
        length: SomeSubstitutions,
        *,
        function: Callable[..., list[Any] | None],
        name: str | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.length = length
        self.function = function
        self.name = name

    def execute(self, context: LaunchContext) -> list[Any] | None:
        """The entities of every iteration, in order."""
        text = perform(context, self.length).strip()
        try:
            count = int(text)
        except ValueError:
            raise LaunchError(f"for: the length must be a whole number, not '{text}'") from None
        entities: list[Any] = []
        for index in range(count):
            entities += list(self.function(i=index) or [])
        return entities


class Iteration(Action):
    """One iteration of a frontend loop: its fresh actions, with its values among the locals."""

    def __init__(self, values: dict[str, Any], actions: list[Any]) -> None:
        super().__init__()
        self.values = {k: str(v) for k, v in values.items()}
        self.actions = actions

    def execute(self, context: LaunchContext) -> None:
        """Process the actions with the iteration's values visible to their substitutions."""
        outer = context.locals.get(_LOCALS, {})
        context.locals[_LOCALS] = {**outer, **self.values}
        try:
            process(self.actions, context)
        finally:
            context.locals[_LOCALS] = outer

    def children(self) -> list[Any]:
        """The iteration's actions."""
        return list(self.actions)


def frontend_body(build: Callable[[], list[Any]]) -> Callable[..., list[Any]]:
    """A loop's function for a frontend: fresh child actions per iteration, values as locals."""

    def body(**values: Any) -> list[Any]:
        return [Iteration(values, build())]

    return body


class ForEachVar(Substitution):
    """The value of a loop variable in the current iteration (``$(for-var NAME [DEFAULT])``)."""

    def __init__(self, name: SomeSubstitutions, *, default_value: SomeSubstitutions = None) -> None:
        self.name = name
        self.default_value = default_value

    def perform(self, context: LaunchContext) -> str:
        """The variable's value."""
        name = perform(context, self.name)
        values = context.locals.get(_LOCALS, {})
        if name in values:
            return str(values[name])
        if self.default_value is not None:
            return perform(context, self.default_value)
        known = ", ".join(sorted(values)) or "none here"
        raise LaunchError(f"loop variable '{name}' is not set (this iteration has: {known})")

    def describe(self) -> str:
        """``ForEachVar('name')``."""
        return f"ForEachVar({describe(self.name)})"


class ForLoopIndex(ForEachVar):
    """The index of the named for-loop in the current iteration (``$(index NAME)``)."""

    def __init__(self, name: SomeSubstitutions) -> None:
        super().__init__(name)


__all__ = ["ForEach", "ForEachVar", "ForLoop", "ForLoopIndex"]
