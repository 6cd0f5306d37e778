"""LaunchDescription, the Action base, conditions, and the walk that processes them in order."""

from __future__ import annotations

import os
import re
import sys
import sysconfig
import traceback
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosl.launch.errors import LaunchError
from rosl.launch.substitutions import SomeSubstitutions, perform

if TYPE_CHECKING:
    from collections.abc import Iterable

    from rosl.launch.context import LaunchContext

_ROSL_DIR = str(Path(__file__).resolve().parents[1]) + os.sep
_LOCATED = re.compile(r"^\S+:\d+: ")


def creation_site() -> str | None:
    """``file:line`` of the innermost caller outside rosl (where a launch file made an action)."""
    frame = sys._getframe(1)
    while frame is not None:
        name = frame.f_code.co_filename
        if not name.startswith((_ROSL_DIR, "<")):
            return f"{name}:{frame.f_lineno}"
        frame = frame.f_back  # type: ignore[assignment]
    return None


_LIBRARIES = tuple(
    {sysconfig.get_paths()[k] + os.sep for k in ("stdlib", "platstdlib", "purelib", "platlib")}
)


def user_error(err: BaseException) -> LaunchError | None:
    """``file:line: Type: message`` when ``err`` was raised by a launch file's own code.

    The innermost frame outside Python's and the installed libraries decides: a launch file's
    (the user's mistake: one line), or rosl's (a bug: None, so its traceback is kept).
    """
    for frame in reversed(traceback.extract_tb(err.__traceback__)):
        name = frame.filename
        if name.startswith(_LIBRARIES) and not name.startswith(_ROSL_DIR):
            continue
        if name.startswith((_ROSL_DIR, "<")):
            return None
        return LaunchError(f"{name}:{frame.lineno}: {type(err).__name__}: {err}")
    return None


def located(error: LaunchError, location: str | None, context: LaunchContext) -> LaunchError:
    """The error with ``file:line:`` of the action it came from, unless it names a line already.

    A ``file: `` prefix naming the file being processed gives way to the line (the file once).
    """
    text = str(error)
    if location is None or _LOCATED.match(text):
        return error
    for file in (context.current_file, location.rsplit(":", 1)[0]):
        if file is not None:
            text = text.removeprefix(f"{file}: ")
    return LaunchError(f"{location}: {text}")


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
        self.location = creation_site()  # file:line, named by errors raised when it runs

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
            where = getattr(argument, "location", None) or path  # its own line, in its file
            raise LaunchError(
                f"{where}: launch argument '{argument.name}' is required "
                f"({argument.description}); pass it as {argument.name}:=<value>"
            )


def process(entities: Iterable[Any], context: LaunchContext) -> None:
    """Visit entities in order; what an entity returns is processed right after it.

    An action that does its work at once (not a process, not a timer) is complete then, and
    OnExecutionComplete handlers hear of it.
    """
    for entity in entities:
        if entity is None:
            continue
        if not hasattr(entity, "visit"):
            raise LaunchError(
                f"{context.current_file or 'launch description'}: '{entity!r}' is not a launch "
                "action (expected launch actions such as Node(...) in the list)"
            )
        try:
            more = entity.visit(context)
        except LaunchError as err:
            raise located(err, getattr(entity, "location", None), context) from None
        except Exception as err:  # the user's own code (an OpaqueFunction's): one line
            found = user_error(err)
            if found is None:
                raise  # rosl's own bug: keep its traceback
            raise found from None
        if more:
            process(more, context)
        if context.supervisor is not None and not getattr(entity, "completes_later", False):
            context.supervisor.completed(entity, context)


def process_for_event(handler: Any, event: Any, context: LaunchContext) -> None:
    """Run an event handler: what it returns for ``event``, with ``event`` among the locals.

    As launch does: ``LocalSubstitution('event.returncode')`` in its actions reads the event.
    An exception raised by the user's handler function is one line naming its file and line.
    """
    try:
        entities = handler.entities(event, context)
    except LaunchError:
        raise
    except Exception as err:
        found = user_error(err)
        if found is None:
            raise
        raise found from None
    had = "event" in context.locals
    previous = context.locals.get("event")
    context.locals["event"] = event
    try:
        process(entities, context)
    finally:
        if had:
            context.locals["event"] = previous
        else:
            context.locals.pop("event", None)
