"""Collecting launch tests with pytest, as ROS 2's launch_testing plugin does.

A ``test_*.py`` file whose module-level ``generate_test_description`` is decorated with
``@pytest.mark.launch_test`` is one pytest item: the whole launch test (active and
post-shutdown tests) runs as ``rosl launch_test`` runs it; a failure lists each failed test
with its traceback. Launch arguments: ``--launch-args name:=value ...``.

The plugin is loaded by every pytest session of an environment where rosl is installed, so it
decides from the file's syntax tree alone (never importing it) and imports nothing heavy until
it meets a launch test. Where ROS 2's own launch_testing is installed too (a sourced ROS 2),
this plugin steps aside and leaves launch tests to it: two plugins adding one option would
stop every pytest run.
"""

from __future__ import annotations

import ast
import contextlib
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:
    from pathlib import Path

MARK = "launch_test"


def _ros2_plugin_installed() -> bool:
    """Whether another pytest plugin named launch_testing (ROS 2's) is installed."""
    import importlib.metadata

    return any(
        entry.name == "launch_testing" and not entry.value.startswith("rosl.")
        for entry in importlib.metadata.entry_points(group="pytest11")
    )


STEP_ASIDE = _ros2_plugin_installed()


def pytest_addoption(parser: pytest.Parser) -> None:
    """``--launch-args``."""
    if STEP_ASIDE:
        return
    with contextlib.suppress(ValueError):  # a real launch_testing's plugin added it already
        parser.addoption(
            "--launch-args",
            action="append",
            nargs="*",
            default=[],
            help="launch arguments for launch tests (name:=value ...)",
        )


def pytest_configure(config: pytest.Config) -> None:
    """Register the ``launch_test`` marker."""
    config.addinivalue_line(
        "markers", f"{MARK}: mark generate_test_description as a launch test's entry point"
    )


def is_launch_test(path: Path) -> bool:
    """Whether a file defines ``generate_test_description`` marked ``launch_test`` (no import)."""
    try:
        source = path.read_bytes()
    except OSError:
        return False
    if b"generate_test_description" not in source:
        return False
    try:
        tree = ast.parse(source, filename=str(path))
    except (SyntaxError, ValueError):
        return False  # pytest's own import reports it
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name == "generate_test_description":
            for decorator in node.decorator_list:
                target = decorator.func if isinstance(decorator, ast.Call) else decorator
                name = ast.unparse(target)
                if name == MARK or name.endswith(f".{MARK}"):
                    return True
    return False


@pytest.hookimpl(tryfirst=True)
def pytest_pycollect_makemodule(module_path: Path, parent: pytest.Collector) -> Any:
    """Collect a launch test file as one LaunchTestModule; leave other files to pytest."""
    if not STEP_ASIDE and module_path.suffix == ".py" and is_launch_test(module_path):
        return LaunchTestModule.from_parent(parent, path=module_path)
    return None


class LaunchTestFailure(Exception):  # noqa: N818 - launch_testing's name
    """Some tests of a launch test failed (or the launch ended before the active tests did)."""

    def __init__(self, failures: list[tuple[str, str]], problem: str | None) -> None:
        super().__init__(problem or "some test cases have failed")
        self.failures = failures
        self.problem = problem


class LaunchTestModule(pytest.File):
    """A launch test file."""

    def collect(self) -> list[pytest.Item]:
        """One item: the file's launch and all its tests."""
        from rosl.launch.errors import LaunchError
        from rosl.launch.testing.loader import load_test_module, test_runs

        try:
            module = load_test_module(self.path)
            test_runs(module, self.path)
        except LaunchError as err:
            raise self.CollectError(str(err)) from None
        item = LaunchTestItem.from_parent(self, name=module.__name__)
        item.module = module  # its own: two files of one name in two folders stay apart
        return [item]


class LaunchTestItem(pytest.Item):
    """Runs one launch test file's launch and tests."""

    module: Any = None  # the test file's module, loaded at collection

    def runtest(self) -> None:
        """Launch and test; raise LaunchTestFailure when something failed."""
        from rosl.launch.loader import parse_arguments
        from rosl.launch.testing.loader import test_runs
        from rosl.launch.testing.test_runner import LaunchTestRunner

        given = [text for group in self.config.getoption("--launch-args") or [] for text in group]
        failures: list[tuple[str, str]] = []
        problems: list[str] = []
        for test_run in test_runs(self.module, self.path):  # fresh test cases every run
            result = LaunchTestRunner(test_run, parse_arguments(given)).run()
            if result.interrupted:
                raise KeyboardInterrupt
            failures += result.failures()
            if result.problem:
                problems.append(f"{test_run.name}: {result.problem}")
        if failures or problems:
            raise LaunchTestFailure(failures, "; ".join(problems) or None)

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException], style: Any = None) -> Any:
        """Each failed test and its traceback, as unittest printed it; one line for a mistake."""
        from rosl.launch.errors import LaunchError

        error = excinfo.value
        if isinstance(error, LaunchTestFailure):
            names = ", ".join(name for name, _ in error.failures)
            parts = [error.problem or f"{len(error.failures)} failed: {names}"]
            parts += [f"{'=' * 70}\nFAIL: {n}\n{'-' * 70}\n{text}" for n, text in error.failures]
            return "\n".join(parts)
        if isinstance(error, LaunchError):
            return str(error)
        return super().repr_failure(excinfo)

    def reportinfo(self) -> tuple[Path, int, str]:
        """Where the test is."""
        return self.path, 0, f"launch tests: {self.name}"
