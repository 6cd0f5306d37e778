"""LaunchDescription, the Action base, conditions, and the walk that processes them in order."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.launch.errors import LaunchError
from rosl.launch.substitutions import SomeSubstitutions, perform

if TYPE_CHECKING:
    from collections.abc import Iterable
    from pathlib import Path

    from rosl.launch.context import LaunchContext


class Condition:
    """Base of conditions (launch.conditions)."""

    def evaluate(self, context: LaunchContext) -> bool:
        """Whether the guarded action runs."""
        raise NotImplementedError


def _truth(context: LaunchContext, expression: SomeSubstitutions) -> bool:
    text = perform(context, expression).strip().lower()
    if text in ("true", "1"):
        return True
    if text in ("false", "0"):
        return False
    raise LaunchError(f"Unknown value for condition: '{text}' (expected true/false or 1/0)")


class IfCondition(Condition):
    """Run when the expression is true/1."""

    def __init__(self, predicate_expression: SomeSubstitutions) -> None:
        self.predicate_expression = predicate_expression

    def evaluate(self, context: LaunchContext) -> bool:
        """True when the expression says so."""
        return _truth(context, self.predicate_expression)


class UnlessCondition(Condition):
    """Run when the expression is false/0."""

    def __init__(self, predicate_expression: SomeSubstitutions) -> None:
        self.predicate_expression = predicate_expression

    def evaluate(self, context: LaunchContext) -> bool:
        """True when the expression is false."""
        return not _truth(context, self.predicate_expression)


class Action:
    """Base of every launch action; ``condition=`` guards it."""

    def __init__(self, *, condition: Condition | None = None, **unknown: Any) -> None:
        if unknown:
            raise LaunchError(
                f"{type(self).__name__}() got unsupported argument(s): {', '.join(sorted(unknown))}"
            )
        self.condition = condition

    def visit(self, context: LaunchContext) -> list[Any] | None:
        """Run the action if its condition holds; return further entities to process."""
        if self.condition is not None and not self.condition.evaluate(context):
            return None
        return self.execute(context)

    def execute(self, context: LaunchContext) -> list[Any] | None:
        """Do the action's work."""
        return None

    def children(self) -> list[Any]:
        """Entities nested in this action (for listing declared arguments)."""
        return []


class LaunchDescription:
    """An ordered list of launch entities (launch.LaunchDescription)."""

    def __init__(self, initial_entities: Iterable[Any] | None = None) -> None:
        self.entities = list(initial_entities or [])

    def add_action(self, action: Any) -> None:
        """Append an action."""
        self.entities.append(action)

    add_entity = add_action

    def visit(self, context: LaunchContext) -> list[Any] | None:
        """A description expands to its entities."""
        return list(self.entities)

    def children(self) -> list[Any]:
        """Its entities."""
        return list(self.entities)

    def get_launch_arguments(self) -> list[Any]:
        """Every DeclareLaunchArgument in it (depth first), as ROS 2 lists them."""
        from rosl.launch.actions import DeclareLaunchArgument

        found: list[Any] = []

        def walk(entity: Any, conditional: bool) -> None:
            if isinstance(entity, DeclareLaunchArgument):  # its own condition counts too
                own = getattr(entity, "condition", None) is not None
                entity.conditionally_included = conditional or own
                if entity.name not in [a.name for a in found]:
                    found.append(entity)
            nested = conditional or getattr(entity, "condition", None) is not None
            for child in entity.children() if hasattr(entity, "children") else []:
                walk(child, nested)

        for entity in self.entities:
            walk(entity, False)
        return found


def check_required_arguments(
    description: LaunchDescription, context: LaunchContext, path: Path
) -> None:
    """Refuse a description before anything starts if a required argument was not given.

    As launch's IncludeLaunchDescription does: an argument with no default, declared
    unconditionally anywhere in the description, must be among the given configurations.
    """
    from rosl.launch.actions import DeclareLaunchArgument, IncludeLaunchDescription

    required: list[Any] = []

    def walk(entity: Any, conditional: bool, given: frozenset[str]) -> None:
        if isinstance(entity, DeclareLaunchArgument):
            if not conditional and entity.default_value is None and entity.name not in given:
                required.append(entity)
            return
        nested = conditional or getattr(entity, "condition", None) is not None
        if isinstance(entity, IncludeLaunchDescription):  # the include may supply them
            names = set()
            for name, _ in entity.launch_arguments:
                try:
                    names.add(perform(context, name))
                except Exception:
                    continue
            given = given | names
        for child in entity.children() if hasattr(entity, "children") else []:
            walk(child, nested, given)

    for entity in description.entities:
        walk(entity, False, frozenset())
    for argument in required:
        if argument.name not in context.launch_configurations:
            raise LaunchError(
                f"{path}: launch argument '{argument.name}' is required "
                f"({argument.description}); pass it as {argument.name}:=<value>"
            )


def process(entities: Iterable[Any], context: LaunchContext) -> None:
    """Visit entities in order; what an entity returns is processed right after it."""
    for entity in entities:
        if entity is None:
            continue
        if not hasattr(entity, "visit"):
            raise LaunchError(
                f"{context.current_file or 'launch description'}: '{entity!r}' is not a launch "
                "action (expected launch actions such as Node(...) in the list)"
            )
        more = entity.visit(context)
        if more:
            process(more, context)
