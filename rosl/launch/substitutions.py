"""Substitutions (launch.substitutions / launch_ros.substitutions): values resolved at load time.

Anything accepting a substitution also accepts a plain string, or a list mixing both (which
concatenates), as in ROS 2. Resolution happens while the description is processed, before
any process starts, so a missing launch argument is an error at once, naming it.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING, Any

from rosl.launch.errors import LaunchError

if TYPE_CHECKING:
    from rosl.launch.context import LaunchContext

SomeSubstitutions = Any  # str | Substitution | list of them


class Substitution:
    """Base: ``perform(context)`` gives the text; ``describe()`` shows it unresolved."""

    def perform(self, context: LaunchContext) -> str:
        """Resolve to text."""
        raise NotImplementedError

    def describe(self) -> str:
        """A readable form for ``--show-args``."""
        return type(self).__name__


class TextSubstitution(Substitution):
    """A literal text."""

    def __init__(self, *, text: str) -> None:
        self.text = str(text)

    def perform(self, context: LaunchContext) -> str:
        """The text itself."""
        return self.text

    def describe(self) -> str:
        """The text, quoted."""
        return f"'{self.text}'"


class LaunchConfiguration(Substitution):
    """The value of a launch argument / configuration."""

    def __init__(
        self, variable_name: SomeSubstitutions, *, default: SomeSubstitutions = None
    ) -> None:
        self.variable_name = variable_name
        self.default = default

    def perform(self, context: LaunchContext) -> str:
        """The configuration's value (or the default)."""
        name = perform(context, self.variable_name)
        configurations = context.launch_configurations
        if name in configurations:
            return configurations[name]
        if self.default is not None:
            return perform(context, self.default)
        where = f"{context.current_file}: " if context.current_file else ""
        raise LaunchError(
            f"{where}launch configuration '{name}' is not set: declare it with "
            f"DeclareLaunchArgument('{name}', default_value=...) or pass {name}:=<value>"
        )

    def describe(self) -> str:
        """``LaunchConfig('name')``."""
        return f"LaunchConfig({describe(self.variable_name)})"


class EnvironmentVariable(Substitution):
    """An environment variable's value."""

    def __init__(self, name: SomeSubstitutions, *, default_value: SomeSubstitutions = None) -> None:
        self.name = name
        self.default_value = default_value

    def perform(self, context: LaunchContext) -> str:
        """The variable's value (scoped environment first)."""
        name = perform(context, self.name)
        value = context.scope.environment.get(name, os.environ.get(name))
        if value is not None:
            return value
        if self.default_value is not None:
            return perform(context, self.default_value)
        raise LaunchError(f"environment variable '{name}' is not set and has no default")

    def describe(self) -> str:
        """``EnvVar('NAME')``."""
        return f"EnvVar({describe(self.name)})"


class PathJoinSubstitution(Substitution):
    """Join path parts (each may be a substitution)."""

    def __init__(self, substitutions: list[SomeSubstitutions]) -> None:
        self.substitutions = list(substitutions)

    def perform(self, context: LaunchContext) -> str:
        """The joined path."""
        return os.path.join(*[perform(context, part) for part in self.substitutions])

    def describe(self) -> str:
        """The parts joined with '/'."""
        return " + '/' + ".join(describe(part) for part in self.substitutions)


class FindPackageShare(Substitution):
    """A package's share folder — in rosl, the package's folder."""

    def __init__(self, package: SomeSubstitutions) -> None:
        self.package = package

    def perform(self, context: LaunchContext) -> str:
        """The package folder."""
        from rosl.pkg.errors import PackageError
        from rosl.pkg.manifest import get_package

        try:
            return str(get_package(perform(context, self.package)).path)
        except PackageError as err:
            raise LaunchError(str(err)) from None

    def describe(self) -> str:
        """``Pkg(pkg='name')``, as launch_ros describes it."""
        return f"Pkg(pkg={describe(self.package)})"


FindPackagePrefix = FindPackageShare


class PythonExpression(Substitution):
    """Evaluate a Python expression built from substitutions (``math`` available)."""

    def __init__(self, expression: list[SomeSubstitutions]) -> None:
        self.expression = expression

    def perform(self, context: LaunchContext) -> str:
        """The expression's value as text."""
        text = perform(context, self.expression)
        try:
            return str(eval(text, {"math": math, "__builtins__": {}}))
        except Exception as err:
            raise LaunchError(
                f"PythonExpression '{text}' failed: {type(err).__name__}: {err}"
            ) from None


def perform(context: LaunchContext, value: SomeSubstitutions) -> str:
    """Resolve a string, a substitution, or a list of them (concatenated)."""
    if value is None:
        return ""
    if isinstance(value, Substitution):
        return value.perform(context)
    if isinstance(value, (list, tuple)):
        return "".join(perform(context, part) for part in value)
    return str(value)


def describe(value: SomeSubstitutions) -> str:
    """Describe unresolved text (for ``--show-args``)."""
    if value is None:
        return ""
    if isinstance(value, Substitution):
        return value.describe()
    if isinstance(value, (list, tuple)):
        return " + ".join(describe(part) for part in value)
    return f"'{value}'"


def resolve_value(context: LaunchContext, value: Any) -> Any:
    """Resolve substitutions inside plain data (parameter dicts and lists)."""
    if isinstance(value, Substitution):
        return value.perform(context)
    if isinstance(value, dict):
        return {resolve_value(context, k): resolve_value(context, v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        if (
            value
            and all(isinstance(v, (str, Substitution)) for v in value)
            and any(isinstance(v, Substitution) for v in value)
        ):
            return perform(context, value)  # a concatenation, as ROS 2 treats it
        return [resolve_value(context, v) for v in value]
    return value
