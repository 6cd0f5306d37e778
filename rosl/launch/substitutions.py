"""Substitutions (launch.substitutions / launch_ros.substitutions): values resolved at load time.

Anything accepting a substitution also accepts a plain string, or a list mixing both (which
concatenates), as in ROS 2. Resolution happens while the description is processed, before
any process starts, so a missing launch argument is an error at once, naming it.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from rosl.launch.errors import LaunchError

if TYPE_CHECKING:
    from pathlib import Path

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
        declare = {  # in the words of the file's format
            ".xml": f'<arg name="{name}" default="..."/>',
            ".yaml": f"'- arg: {{name: {name}, default: ...}}'",
            ".yml": f"'- arg: {{name: {name}, default: ...}}'",
        }.get(getattr(context.current_file, "suffix", ""))
        raise LaunchError(
            f"{where}launch configuration '{name}' is not set: declare it with "
            f"{declare or f'DeclareLaunchArgument({name!r}, default_value=...)'} "
            f"or pass {name}:=<value>"
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


class SubstitutionFailure(LaunchError):  # noqa: N818 - launch's name
    """A substitution that cannot be performed (launch.substitutions.SubstitutionFailure)."""


class PathJoinSubstitution(Substitution):
    """Join path parts (each may be a substitution); ``/`` joins one more (launch since Jazzy)."""

    def __init__(self, substitutions: list[SomeSubstitutions]) -> None:
        self.substitutions = list(substitutions)

    def __truediv__(self, other: SomeSubstitutions) -> PathJoinSubstitution:
        return PathJoinSubstitution([*self.substitutions, other])

    def perform(self, context: LaunchContext) -> str:
        """The joined path."""
        return os.path.join(*[perform(context, part) for part in self.substitutions])

    def describe(self) -> str:
        """The parts joined with '/'."""
        return " + '/' + ".join(describe(part) for part in self.substitutions)


class PathSubstitution(PathJoinSubstitution):
    """A path to build on with ``/``: ``PathSubstitution(FindPackageShare('p')) / 'config'``."""

    def __init__(self, path: SomeSubstitutions) -> None:
        super().__init__([path])


class FileContent(Substitution):
    """The text of a file (``$(file-content PATH)``, launch since Jazzy)."""

    def __init__(self, path: SomeSubstitutions) -> None:
        self.path = path

    def perform(self, context: LaunchContext) -> str:
        """The file's text."""
        path = perform(context, self.path)
        try:
            with open(path, encoding="utf-8") as file:
                return file.read()
        except (OSError, UnicodeDecodeError) as err:
            why = err.strerror if isinstance(err, OSError) else "not UTF-8 text"
            raise SubstitutionFailure(f"cannot read file {path}: {why}") from None

    def describe(self) -> str:
        """``FileContent(path)``."""
        return f"FileContent({describe(self.path)})"


class LaunchLogDir(Substitution):
    """The launch's log folder (``$(launch-log-dir)``)."""

    def perform(self, context: LaunchContext) -> str:
        """The folder the launcher logs to."""
        supervisor = context.supervisor
        if supervisor is None:
            raise SubstitutionFailure("LaunchLogDir used outside of a running launch")
        return str(supervisor.log_dir)

    def describe(self) -> str:
        """``LaunchLogDir()``."""
        return "LaunchLogDir()"


class FindPackage(Substitution):
    """A package's prefix — in rosl, the package's folder (launch_ros.substitutions)."""

    def __init__(self, package: SomeSubstitutions) -> None:
        self.package = package

    @classmethod
    def find(cls, package: str) -> str:
        """The folder of ``package``, without a launch context.

        Raises:
            LaunchError: no such package.
        """
        from rosl.pkg.errors import PackageError
        from rosl.pkg.manifest import get_package

        try:
            return str(get_package(package).path)
        except PackageError as err:
            raise LaunchError(str(err)) from None

    def perform(self, context: LaunchContext) -> str:
        """The package folder."""
        return self.find(perform(context, self.package))

    def describe(self) -> str:
        """``Pkg(pkg='name')``, as launch_ros describes it."""
        return f"Pkg(pkg={describe(self.package)})"


class FindPackagePrefix(FindPackage):
    """``$(find-pkg-prefix P)``: the package's prefix (its folder in rosl)."""


class FindPackageShare(FindPackage):
    """``$(find-pkg-share P)``: the package's share folder (its folder in rosl)."""


class ExecutableInPackage(FindPackage):
    """The path of a package's executable (launch_ros.substitutions.ExecutableInPackage).

    rosl's executables are often Python entry points (``module:main``) rather than files; those
    have no path of their own, and ``command()`` gives the argv that starts them.
    """

    def __init__(self, executable: SomeSubstitutions, package: SomeSubstitutions) -> None:
        super().__init__(package)
        self.executable = executable

    def command(self, context: LaunchContext) -> list[str]:
        """The argv that starts the executable (its path, or rosl's entry for a module)."""
        from rosl.pkg.errors import PackageError
        from rosl.pkg.executables import command_line, find_executable

        try:
            found = find_executable(
                perform(context, self.package), perform(context, self.executable)
            )
            return command_line(found, [])
        except PackageError as err:
            raise LaunchError(str(err)) from None

    def perform(self, context: LaunchContext) -> str:
        """The executable's path."""
        argv = self.command(context)
        if len(argv) != 1:
            raise LaunchError(
                f"executable '{perform(context, self.executable)}' of package "
                f"'{perform(context, self.package)}' is a Python entry point, not a file; "
                "start it with a node (Node(package=, executable=) or <node pkg= exec=>)"
            )
        return argv[0]

    def describe(self) -> str:
        """``ExecInPkg(pkg='p', exec='e')``."""
        return f"ExecInPkg(pkg={describe(self.package)}, exec={describe(self.executable)})"


def rosl_executable(path: str | None = None) -> str | None:
    """The ``rosl`` command (on the PATH, or beside this Python), which takes ``ros2``'s words."""
    import shutil
    import sys
    from pathlib import Path

    beside = Path(sys.executable).with_name("rosl")
    if beside.is_file() and os.access(beside, os.X_OK):
        return str(beside)
    return shutil.which("rosl", path=path)


class FindExecutable(Substitution):
    """The path of an executable found on the PATH (``$(find-exec NAME)``).

    Where no ``ros2`` is installed, ``FindExecutable(name='ros2')`` is rosl's own command, so a
    launch file's ``ros2 ...`` commands run rosl's same words.
    """

    def __init__(self, *, name: SomeSubstitutions) -> None:
        self.name = name

    def perform(self, context: LaunchContext) -> str:
        """The executable's full path."""
        import shutil

        name = perform(context, self.name)
        path = context.scope.environment.get("PATH", os.environ.get("PATH"))
        found = shutil.which(name, path=path)
        if found is None and name == "ros2":  # no ROS 2 here: rosl says the same words
            found = rosl_executable(path)
        if found is None:
            raise LaunchError(f"executable '{name}' not found on the PATH")
        return found

    def describe(self) -> str:
        """``FindExec('name')``."""
        return f"FindExec({describe(self.name)})"


class ThisLaunchFile(Substitution):
    """The path of the launch file being processed (``$(filename)``)."""

    def __init__(self, *, path: Path | None = None) -> None:
        self.path = path  # a frontend (XML/YAML) knows its file when it reads it

    def _file(self, context: LaunchContext) -> Path:
        if self.path is not None:
            return self.path
        if context.current_file is None:
            raise LaunchError(f"{type(self).__name__} used outside of a launch file")
        return context.current_file.resolve()  # absolute, as the loader names files

    def perform(self, context: LaunchContext) -> str:
        """The file's absolute path."""
        return str(self._file(context))

    def describe(self) -> str:
        """``ThisLaunchFile()``."""
        return f"{type(self).__name__}()"


class ThisLaunchFileDir(ThisLaunchFile):
    """The folder of the launch file being processed (``$(dirname)``)."""

    def perform(self, context: LaunchContext) -> str:
        """The file's folder."""
        return str(self._file(context).parent)


class AnonName(Substitution):
    """A name made unique for this launch: the same ``name`` gives the same result."""

    def __init__(self, name: SomeSubstitutions) -> None:
        self.name = name

    def perform(self, context: LaunchContext) -> str:
        """``name_<pid>_<random>``, fixed per name for the whole launch."""
        import random

        name = perform(context, self.name)
        names: dict[str, str] = context.locals.setdefault("anon", {})
        if name not in names:
            names[name] = f"{name}_{os.getpid()}_{random.randrange(1 << 62)}"
        return names[name]

    def describe(self) -> str:
        """``AnonName('name')``."""
        return f"AnonName({describe(self.name)})"


class PythonExpression(Substitution):
    """Evaluate a Python expression built from substitutions.

    As in launch: the names of ``math`` are there directly (``pi``, ``sin``), each module of
    ``python_modules`` under its name, and Python's builtins (``int``, ``len``).
    """

    def __init__(
        self, expression: SomeSubstitutions, python_modules: SomeSubstitutions = ("math",)
    ) -> None:
        self.expression = expression
        self.python_modules = python_modules

    def _scope(self, context: LaunchContext) -> dict[str, Any]:
        import importlib

        modules = self.python_modules
        entries = [modules] if isinstance(modules, (str, Substitution)) else list(modules)
        scope: dict[str, Any] = {}
        for entry in entries:
            name = perform(context, entry).strip()
            try:
                module = importlib.import_module(name)
            except ImportError:
                raise LaunchError(f"PythonExpression: no Python module '{name}'") from None
            if name == "math":
                scope.update(vars(module))
            scope[name] = module
        return scope

    def perform(self, context: LaunchContext) -> str:
        """The expression's value as text."""
        scope = self._scope(context)
        text = perform(context, self.expression)
        try:
            return str(eval(text, {}, scope))
        except Exception as err:
            raise LaunchError(
                f"PythonExpression '{text}' failed: {type(err).__name__}: {err}"
            ) from None

    def describe(self) -> str:
        """``PythonExpr(expression)``."""
        return f"PythonExpr({describe(self.expression)})"


class Command(Substitution):
    """The standard output of a command (``$(command '...' [fail|warn|ignore|capture])``).

    The command text is split into words as a shell would (``shlex``) and run without a shell,
    for at most ``TIMEOUT_SEC``. ``on_stderr``: ``fail`` (anything on stderr is an error),
    ``warn`` (logged), ``ignore``, or ``capture`` (kept with stdout). A failing command is an
    error naming it.
    """

    TIMEOUT_SEC = 120.0

    def __init__(
        self, command: SomeSubstitutions, *, on_stderr: SomeSubstitutions = "fail"
    ) -> None:
        self.command = command
        self.on_stderr = on_stderr

    def perform(self, context: LaunchContext) -> str:
        """Run the command; its standard output."""
        import shlex

        text = perform(context, self.command)
        mode = perform(context, self.on_stderr)
        if mode not in ("fail", "warn", "ignore", "capture"):
            raise LaunchError(
                f"command '{text}': on_stderr is '{mode}', not one of fail, warn, ignore, capture"
            )
        try:
            argv = shlex.split(text)
        except ValueError as bad:
            raise LaunchError(f"command '{text}' cannot be split into words: {bad}") from None
        if not argv:
            raise LaunchError("a command substitution with no command")
        code, out, err = self._run(text, argv, mode, {**os.environ, **context.scope.environment})
        if code != 0:
            said = f": {err.splitlines()[-1]}" if err else ""
            raise LaunchError(f"command '{text}' exited with code {code}{said}")
        if err and mode == "fail":
            raise LaunchError(
                f"command '{text}' wrote to stderr: {err.splitlines()[0]} (give 'warn' or "
                "'ignore' as its second argument to allow that)"
            )
        if err and mode == "warn" and context.supervisor is not None:
            context.supervisor.log("WARNING", "launch", f"command '{text}' wrote to stderr: {err}")
        return out

    def _run(
        self, text: str, argv: list[str], mode: str, env: dict[str, str]
    ) -> tuple[int, str, str]:
        import subprocess

        try:
            done = subprocess.run(
                argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT if mode == "capture" else subprocess.PIPE,
                text=True, env=env, timeout=self.TIMEOUT_SEC, check=False,
            )  # fmt: skip
        except FileNotFoundError:
            raise LaunchError(f"command '{text}' failed: '{argv[0]}' not found") from None
        except OSError as err:
            raise LaunchError(f"command '{text}' failed: {err.strerror}") from None
        except subprocess.TimeoutExpired:
            raise LaunchError(
                f"command '{text}' did not finish within {self.TIMEOUT_SEC:g} s"
            ) from None
        return done.returncode, done.stdout or "", (done.stderr or "").strip()

    def describe(self) -> str:
        """``Command(...)``."""
        return f"Command({describe(self.command)})"


class LocalSubstitution(Substitution):
    """A value from the context's locals, as an event handler's actions see them.

    ``LocalSubstitution('event.returncode')`` in the actions of an OnProcessExit handler is the
    exit code of the process that ended (``event.action``, ``event.pid``, ...).
    """

    def __init__(self, expression: str, description: str | None = None) -> None:
        self.expression = expression
        self.description = description

    def perform(self, context: LaunchContext) -> str:
        """The expression's value, read from the locals."""
        head, _, rest = self.expression.partition(".")
        if head not in context.locals:
            known = ", ".join(sorted(k for k in context.locals if k != "anon")) or "none"
            raise LaunchError(
                f"LocalSubstitution('{self.expression}'): no local '{head}' here (locals: "
                f"{known}; 'event' exists only in the actions of an event handler)"
            )
        value = context.locals[head]
        for name in rest.split(".") if rest else []:
            try:
                value = value[name] if isinstance(value, dict) else getattr(value, name)
            except (AttributeError, KeyError):
                raise LaunchError(
                    f"LocalSubstitution('{self.expression}'): {type(value).__name__} has no "
                    f"'{name}'"
                ) from None
        return str(value)

    def describe(self) -> str:
        """``LocalVar('expression')``."""
        return self.description or f"LocalVar('{self.expression}')"


def perform(context: LaunchContext, value: SomeSubstitutions) -> str:
    """Resolve a string, a substitution, or a list of them (concatenated)."""
    if value is None:
        return ""
    if isinstance(value, Substitution):
        return value.perform(context)
    if isinstance(value, (list, tuple)):
        return "".join(perform(context, part) for part in value)
    return str(value)


def normalize(value: SomeSubstitutions) -> list[Substitution]:
    """A value as a list of substitutions, text as TextSubstitution (launch.utilities')."""
    if value is None:
        return []
    if isinstance(value, Substitution):
        return [value]
    if isinstance(value, (list, tuple)):
        return [part for item in value for part in normalize(item)]
    return [TextSubstitution(text=str(value))]


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
