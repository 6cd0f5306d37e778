"""The state a launch description is processed in: arguments, scopes, namespace, environment."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.launch.supervisor import Supervisor


@dataclass(slots=True)
class Scope:
    """What a GroupAction (or the top level) sees: configurations, namespace, env, params."""

    configurations: dict[str, str] = field(default_factory=dict)
    namespace: str = ""
    environment: dict[str, str] = field(default_factory=dict)
    unset: set[str] = field(default_factory=set)  # removed from the environment (UnsetEnv...)
    parameters: list[Any] = field(default_factory=list)  # (name, value) or a ParameterFile
    remappings: list[tuple[str, str]] = field(default_factory=list)


class LaunchContext:
    """Where substitutions resolve and actions take effect (launch.LaunchContext)."""

    def __init__(self, supervisor: Supervisor | None, arguments: dict[str, str]) -> None:
        self.supervisor = supervisor
        self._scopes = [Scope(configurations=dict(arguments))]
        self.declared: list[Any] = []  # DeclareLaunchArgument actions seen, in order
        self.files: list[Path] = []  # launch files being processed (innermost last)
        self.locals: dict[str, Any] = {}

    @property
    def scope(self) -> Scope:
        """The innermost scope."""
        return self._scopes[-1]

    @property
    def launch_configurations(self) -> dict[str, str]:
        """The launch configurations in force (rclpy-compatible name)."""
        return self.scope.configurations

    @property
    def environment(self) -> dict[str, str]:
        """The environment processes started now get (launch.LaunchContext.environment)."""
        found = {**os.environ, **self.scope.environment}
        for name in self.scope.unset:
            found.pop(name, None)
        return found

    def perform_substitution(self, substitution: Any) -> str:
        """A substitution's text in this context (launch.LaunchContext.perform_substitution)."""
        from rosl.launch.substitutions import perform

        return perform(self, substitution)

    @property
    def current_file(self) -> Path | None:
        """The launch file being processed."""
        return self.files[-1] if self.files else None

    def push(
        self, *, forwarding: bool = True, configurations: dict[str, str] | None = None
    ) -> None:
        """Open a scope (GroupAction with scoped=True)."""
        outer = self.scope
        self._scopes.append(
            Scope(
                configurations={
                    **(outer.configurations if forwarding else {}),
                    **(configurations or {}),
                },
                namespace=outer.namespace,
                environment=dict(outer.environment),
                unset=set(outer.unset),
                parameters=list(outer.parameters),
                remappings=list(outer.remappings),
            )
        )

    def pop(self) -> None:
        """Close the innermost scope."""
        if len(self._scopes) > 1:
            self._scopes.pop()

    def push_namespace(self, namespace: str) -> None:
        """PushRosNamespace: relative namespaces nest, absolute ones replace."""
        namespace = namespace.strip()
        if namespace.startswith("/"):
            self.scope.namespace = namespace.rstrip("/")
        elif namespace:
            self.scope.namespace = f"{self.scope.namespace}/{namespace.strip('/')}"
