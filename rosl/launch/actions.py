"""The core launch actions (launch.actions), event handlers and events."""

from __future__ import annotations

import os
import shlex
import shutil
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosl.launch.description import (
    Action,
    Condition,
    LaunchDescription,
    check_required_arguments,
    process,
)
from rosl.launch.errors import LaunchError
from rosl.launch.event_handlers import OnProcessExit as OnProcessExit  # the supervisor's
from rosl.launch.substitutions import (
    ExecutableInPackage,
    SomeSubstitutions,
    perform,
    resolve_value,
)

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.launch.context import LaunchContext

DEFAULT_DESCRIPTION = "no description given"
# where no `ros2` is installed, a launch file's `ros2 ...` command runs rosl's same words
ROS2 = [sys.executable, "-m", "rosl"]


class DeclareLaunchArgument(Action):
    """Declare a launch argument, with a default and a description."""

    def __init__(
        self,
        name: str,
        *,
        default_value: SomeSubstitutions = None,
        description: str = DEFAULT_DESCRIPTION,
        choices: list[str] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.name = name
        self.default_value = default_value
        if choices is not None:  # as launch words it, for `--show-args`
            if description == DEFAULT_DESCRIPTION:
                description = f"One of: {choices}"
            else:
                stop = "" if description.endswith(".") else "."
                description = f"{description}{stop} Valid choices are: {choices}"
        self.description = description
        self.choices = choices
        self.conditionally_included = False

    def execute(self, context: LaunchContext) -> None:
        """Take the given value, or the default; a missing one is an error saying how to pass it."""
        context.declared.append(self)
        configurations = context.launch_configurations
        if self.name not in configurations:
            if self.default_value is None:
                where = f"{context.current_file}: " if context.current_file else ""
                raise LaunchError(
                    f"{where}launch argument '{self.name}' is required ({self.description}); "
                    f"pass it as {self.name}:=<value>"
                )
            configurations[self.name] = perform(context, self.default_value)
        if self.choices and configurations[self.name] not in self.choices:
            raise LaunchError(
                f"launch argument '{self.name}' is '{configurations[self.name]}', but must be "
                f"one of: {', '.join(self.choices)}"
            )


class SetLaunchConfiguration(Action):
    """Set a launch configuration."""

    def __init__(self, name: SomeSubstitutions, value: SomeSubstitutions, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.name = name
        self.value = value

    def execute(self, context: LaunchContext) -> None:
        """Set it in the current scope."""
        context.launch_configurations[perform(context, self.name)] = perform(context, self.value)


class ResetLaunchConfigurations(Action):
    """Forget the launch configurations of this scope, but those given (name -> value)."""

    def __init__(
        self, launch_configurations: dict[SomeSubstitutions, SomeSubstitutions] | None = None,
        **kwargs: Any,
    ) -> None:  # fmt: skip
        super().__init__(**kwargs)
        self.launch_configurations = launch_configurations

    def execute(self, context: LaunchContext) -> None:
        """Clear the scope's configurations, then set the given ones."""
        kept = {
            perform(context, k): perform(context, v)
            for k, v in (self.launch_configurations or {}).items()
        }
        context.launch_configurations.clear()
        context.launch_configurations.update(kept)


class SetEnvironmentVariable(Action):
    """Set an environment variable for processes started after it (in this scope)."""

    def __init__(self, name: SomeSubstitutions, value: SomeSubstitutions, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.name = name
        self.value = value

    def execute(self, context: LaunchContext) -> None:
        """Record it in the scope's environment."""
        name = perform(context, self.name)
        context.scope.environment[name] = perform(context, self.value)
        context.scope.unset.discard(name)


class UnsetEnvironmentVariable(Action):
    """Remove an environment variable for processes started after it (in this scope)."""

    def __init__(self, name: SomeSubstitutions, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.name = name

    def execute(self, context: LaunchContext) -> None:
        """Record the removal in the scope."""
        name = perform(context, self.name)
        context.scope.environment.pop(name, None)
        context.scope.unset.add(name)


class AppendEnvironmentVariable(Action):
    """Append (or prepend) to an environment variable, or set it if it is not set."""

    def __init__(
        self,
        name: SomeSubstitutions,
        value: SomeSubstitutions,
        prepend: bool | SomeSubstitutions = False,
        separator: SomeSubstitutions = os.pathsep,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.name = name
        self.value = value
        self.prepend = prepend
        self.separator = separator

    def execute(self, context: LaunchContext) -> None:
        """Join the value to the variable as the scope (or this process) has it."""
        name = perform(context, self.name)
        value = perform(context, self.value)
        separator = perform(context, self.separator)
        current = context.environment.get(name)
        if current is None:
            joined = value
        elif _flag(context, self.prepend):
            joined = value + separator + current
        else:
            joined = current + separator + value
        context.scope.environment[name] = joined
        context.scope.unset.discard(name)


class LogInfo(Action):
    """Print a line from the launch file: ``[INFO] [launch.user]: ...``."""

    def __init__(self, *, msg: SomeSubstitutions, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.msg = msg

    def execute(self, context: LaunchContext) -> None:
        """Log it."""
        if context.supervisor is not None:
            context.supervisor.log("INFO", "launch.user", perform(context, self.msg))


class GroupAction(Action):
    """Run actions in their own scope (configurations, namespace, environment)."""

    def __init__(
        self,
        actions: list[Any],
        *,
        scoped: bool = True,
        forwarding: bool = True,
        launch_configurations: dict[str, SomeSubstitutions] | None = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.actions = list(actions)
        self.scoped = scoped
        self.forwarding = forwarding
        self.launch_configurations = launch_configurations or {}

    def execute(self, context: LaunchContext) -> None:
        """Process the actions inside a scope."""
        values = {
            perform(context, k): perform(context, v) for k, v in self.launch_configurations.items()
        }
        if self.scoped:
            context.push(forwarding=self.forwarding, configurations=values)
        else:
            context.launch_configurations.update(values)
        try:
            process(self.actions, context)
        finally:
            if self.scoped:
                context.pop()

    def children(self) -> list[Any]:
        """The grouped actions."""
        return list(self.actions)


class IncludeLaunchDescription(Action):
    """Include another launch file, with launch arguments."""

    def __init__(
        self,
        launch_description_source: Any,
        *,
        launch_arguments: Any = None,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.launch_description_source = launch_description_source
        self.launch_arguments = (
            list(dict(launch_arguments).items())
            if isinstance(launch_arguments, dict)
            else list(launch_arguments or [])
        )

    def execute(self, context: LaunchContext) -> None:
        """Load the file and process its description with the given arguments."""
        from rosl.launch.loader import load_description

        source = self.launch_description_source
        path = Path(perform(context, getattr(source, "location", source))).expanduser().resolve()
        for name, value in self.launch_arguments:
            context.launch_configurations[perform(context, name)] = perform(context, value)
        description = load_description(path)
        check_required_arguments(description, context, path)
        context.files.append(path)
        try:
            process(description.entities, context)
        finally:
            context.files.pop()

    def children(self) -> list[Any]:
        """The included file's entities, when the path needs no launch configuration."""
        from rosl.launch.context import LaunchContext
        from rosl.launch.loader import load_description

        location = getattr(self.launch_description_source, "location", None)
        try:  # as launch does: the path expanded with an empty context
            path = Path(perform(LaunchContext(None, {}), location))
            if path.is_file():
                return load_description(path).entities
        except Exception:
            return []
        return []


class PythonLaunchDescriptionSource:
    """A Python launch file to include (launch.launch_description_sources)."""

    def __init__(self, launch_file_path: SomeSubstitutions) -> None:
        self.location = launch_file_path


AnyLaunchDescriptionSource = PythonLaunchDescriptionSource
FrontendLaunchDescriptionSource = PythonLaunchDescriptionSource
YAMLLaunchDescriptionSource = PythonLaunchDescriptionSource
XMLLaunchDescriptionSource = PythonLaunchDescriptionSource  # the file's suffix decides


class ExecuteProcess(Action):
    """Start a process (launch.actions.ExecuteProcess)."""

    completes_later = True  # when the process has exited (OnExecutionComplete)

    def __init__(
        self,
        *,
        cmd: list[SomeSubstitutions] | SomeSubstitutions,
        name: SomeSubstitutions = None,
        cwd: SomeSubstitutions = None,
        env: dict[str, SomeSubstitutions] | None = None,
        additional_env: dict[str, SomeSubstitutions] | None = None,
        shell: bool = False,
        output: str = "log",
        respawn: bool | SomeSubstitutions = False,
        respawn_delay: float | None = None,
        respawn_max_retries: int = -1,
        cached_output: bool = False,
        emulate_tty: bool = False,
        sigterm_timeout: SomeSubstitutions = None,
        sigkill_timeout: SomeSubstitutions = None,
        prefix: SomeSubstitutions = None,
        on_exit: Any = None,
        log_cmd: bool = False,
        **kwargs: Any,
    ) -> None:
        super().__init__(**kwargs)
        self.cmd = cmd
        self.name = name
        self.cwd = cwd
        self.env = env
        self.additional_env = additional_env
        self.shell = shell
        self.output = output
        self.respawn = respawn
        self.respawn_delay = respawn_delay or 0.0
        self.respawn_max_retries = int(respawn_max_retries)  # -1: no limit
        del cached_output  # every line reaches the handlers as it comes
        self.emulate_tty = emulate_tty
        self.sigterm_timeout = sigterm_timeout
        self.sigkill_timeout = sigkill_timeout
        self.prefix = prefix
        self.on_exit = on_exit
        del log_cmd

    def command(self, context: LaunchContext) -> list[str]:
        """The resolved command line (``/bin/sh -c ...`` with ``shell``)."""
        return self._wrapped(self.words(context))

    def _wrapped(self, argv: list[str]) -> list[str]:
        if self.shell:
            return ["/bin/sh", "-c", " ".join(shlex.quote(a) if a in ROS2 else a for a in argv)]
        return argv

    def words(self, context: LaunchContext) -> list[str]:
        """The command's words as given, resolved (not yet handed to a shell)."""
        parts = self.cmd if isinstance(self.cmd, list) else [self.cmd]
        argv: list[str] = []
        for part in parts:  # a package's executable may be a Python entry: its whole argv
            if isinstance(part, ExecutableInPackage):
                argv += part.command(context)
            else:
                argv.append(perform(context, part))
        if argv and argv[0] == "ros2" and shutil.which("ros2") is None:
            argv = [*ROS2, *argv[1:]]  # `ros2 bag record ...` in a launch file: rosl's words
        return argv

    def base_name(self, context: LaunchContext, argv: list[str]) -> str:
        """The name shown as ``[name-N]``."""
        if self.name is not None:
            return perform(context, self.name)
        first = self.cmd[0] if isinstance(self.cmd, list) and self.cmd else self.cmd
        if isinstance(first, ExecutableInPackage):  # its file's name, even for a Python entry
            return perform(context, first.executable)
        if argv[: len(ROS2)] == ROS2:
            return "ros2"
        return os.path.basename(argv[0]) if argv else "process"

    def environment(self, context: LaunchContext) -> dict[str, str]:
        """The environment the process starts with."""
        if self.env is not None:
            env = {perform(context, k): perform(context, v) for k, v in self.env.items()}
        else:
            env = context.environment
        for key, value in (self.additional_env or {}).items():
            env[perform(context, key)] = perform(context, value)
        return env

    def execute(self, context: LaunchContext) -> None:
        """Hand the process to the supervisor."""
        from rosl.launch.records import ProcessSpec

        if self.shell:  # named after its command, not after the shell (substituted once)
            words = self.words(context)
            argv = self._wrapped(words)
        else:
            argv = words = self.command(context)
        prefix = perform(context, self.prefix) if self.prefix is not None else ""
        spec = ProcessSpec(
            name=self.base_name(context, words),
            cmd=[*shlex.split(prefix), *argv],
            env=self.environment(context),
            cwd=perform(context, self.cwd) if self.cwd is not None else None,
            output=str(perform(context, self.output)),
            respawn=_flag(context, self.respawn),
            respawn_delay=float(self.respawn_delay),
            respawn_max_retries=self.respawn_max_retries,
            emulate_tty=self.emulate_tty,
            sigterm_timeout=_seconds(context, self.sigterm_timeout, "sigterm_timeout"),
            sigkill_timeout=_seconds(context, self.sigkill_timeout, "sigkill_timeout"),
            details=self.details(context),
        )
        if context.supervisor is not None:
            context.supervisor.start(spec, self, context)

    def details(self, context: LaunchContext) -> dict[str, Any]:
        """What ``--print`` shows besides the command line."""
        return {}


def _flag(context: LaunchContext, value: Any) -> bool:
    if isinstance(value, bool):
        return value
    return perform(context, value).strip().lower() in ("true", "1", "yes", "on")


def _seconds(context: LaunchContext, value: Any, configuration: str) -> float:
    text = (
        perform(context, value)
        if value is not None
        else context.launch_configurations.get(configuration, "5")
    )
    try:
        return float(text)
    except ValueError:
        raise LaunchError(f"{configuration} must be a number of seconds, not '{text}'") from None


class TimerAction(Action):
    """Run actions after a delay."""

    completes_later = True  # when its actions have run (OnExecutionComplete)

    def __init__(
        self, *, period: float | SomeSubstitutions, actions: list[Any], **kwargs: Any
    ) -> None:
        super().__init__(**kwargs)
        self.period = period
        self.actions = list(actions)

    def execute(self, context: LaunchContext) -> None:
        """Schedule the actions."""
        text = (
            perform(context, self.period)
            if not isinstance(self.period, (int, float))
            else str(self.period)
        )
        try:
            seconds = float(text)
        except ValueError:
            seconds = -1.0
        if not seconds >= 0:  # (NaN too)
            raise LaunchError(f"a timer's period must be a number of seconds >= 0, not '{text}'")
        supervisor = context.supervisor
        if supervisor is not None:

            def fire() -> None:
                process(self.actions, context)
                supervisor.completed(self, context)

            supervisor.call_later(seconds, fire)

    def children(self) -> list[Any]:
        """The delayed actions."""
        return list(self.actions)


class OpaqueFunction(Action):
    """Call a function with the launch context; it may return more actions."""

    def __init__(
        self,
        *,
        function: Callable[..., Any],
        args: list[Any] | None = None,
        kwargs: dict[str, Any] | None = None,
        **rest: Any,
    ) -> None:
        super().__init__(**rest)
        self.function = function
        self.args = args or []
        self.kwargs = kwargs or {}

    def execute(self, context: LaunchContext) -> list[Any] | None:
        """Call the function."""
        result = self.function(context, *self.args, **self.kwargs)
        return list(result) if result else None


class Shutdown(Action):
    """Shut the whole launch down (launch.actions.Shutdown, and the Shutdown event)."""

    def __init__(
        self, *, reason: str = "shutdown requested", due_to_sigint: bool = False, **kwargs: Any
    ) -> None:
        super().__init__(**kwargs)
        self.reason = reason
        self.due_to_sigint = due_to_sigint

    def execute(self, context: LaunchContext) -> None:
        """Ask the supervisor to stop everything."""
        if context.supervisor is not None:
            context.supervisor.shutdown(self.reason)


class EmitEvent(Action):
    """Emit an event: ``Shutdown``, ``ShutdownProcess``/``SignalProcess`` or ``ChangeState``."""

    def __init__(self, *, event: Any, **kwargs: Any) -> None:
        from rosl.launch.events import ProcessTargetedEvent
        from rosl.launch.lifecycle_events import ChangeState

        super().__init__(**kwargs)
        if not isinstance(event, (Shutdown, ProcessTargetedEvent, ChangeState)):
            raise LaunchError(
                f"EmitEvent(event={type(event).__name__}(...)) is not supported by rosl: "
                "the events it emits are launch.events.Shutdown, "
                "launch.events.process.ShutdownProcess / SignalProcess and "
                "launch_ros.events.lifecycle.ChangeState"
            )
        self.event = event

    def execute(self, context: LaunchContext) -> list[Any] | None:
        """Act on the event."""
        from rosl.launch.events import ProcessTargetedEvent, emit_to_processes

        if isinstance(self.event, ProcessTargetedEvent):
            if context.supervisor is not None:
                emit_to_processes(self.event, context.supervisor)
            return None
        return [self.event]


class LaunchConfigurationEquals(Condition):
    """True when a launch configuration has the given value (launch.conditions).

    With ``expected_value=None``, true when the configuration is not set.
    """

    def __init__(self, launch_configuration_name: str, expected_value: SomeSubstitutions) -> None:
        self.launch_configuration_name = launch_configuration_name
        self.expected_value = expected_value

    def evaluate(self, context: LaunchContext) -> bool:
        """Compare the configuration with the expected value."""
        value = context.launch_configurations.get(self.launch_configuration_name)
        if self.expected_value is None:
            return value is None
        return value == perform(context, self.expected_value)


class LaunchConfigurationNotEquals(LaunchConfigurationEquals):
    """True when a launch configuration does not have the given value."""

    def evaluate(self, context: LaunchContext) -> bool:
        """The opposite of LaunchConfigurationEquals."""
        return not super().evaluate(context)


def launch_description_from(entities: list[Any]) -> LaunchDescription:
    """Wrap a list in a LaunchDescription."""
    return LaunchDescription(entities)


def resolve_parameter_value(context: LaunchContext, value: Any) -> Any:
    """Resolve substitutions inside a parameter value."""
    return resolve_value(context, value)
