"""Reading a launch test file: its module, its launch description and its two sets of tests.

Test classes are ``unittest.TestCase`` subclasses; those marked ``@post_shutdown_test()`` run
after the launch, the others (active tests) while it runs. Each run gets fresh subclasses, so
the values given to the tests (``proc_output``, ``proc_info``, ``test_args``, ...) never leak
into the user's classes. A test method, ``setUp``/``tearDown`` and ``setUpClass``/
``tearDownClass`` receive those values by argument name.
"""

from __future__ import annotations

import functools
import importlib.util
import inspect
import sys
import traceback
import unittest
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosl.launch.errors import LaunchError

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from types import ModuleType

    from rosl.launch.description import LaunchDescription

DEFAULT_READY_TIMEOUT = 15.0


def load_test_module(path: Path, name: str | None = None) -> ModuleType:
    """Import a launch test file (``launch``, ``launch_ros``, ``launch_testing`` served by rosl).

    Raises:
        LaunchError: the file is missing, does not compile, or fails while it is imported.
    """
    import rosl.compat

    path = path.expanduser().resolve()
    if not path.is_file():
        raise LaunchError(f"launch test file {path} does not exist")
    rosl.compat.install(force=True)
    module_name = name or path.name.removesuffix(".py")
    spec = importlib.util.spec_from_file_location(module_name, path)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    try:
        spec.loader.exec_module(module)
    except SyntaxError as err:
        del sys.modules[module_name]
        raise LaunchError(
            f"{path}:{err.lineno}:{err.offset or 0}: syntax error: {err.msg}"
        ) from None
    except Exception as err:
        del sys.modules[module_name]
        raise user_error(path, err) from None
    return module


def user_error(path: Path, err: BaseException) -> LaunchError:
    """``file:line: Type: message`` for an exception raised by the test file's own code."""
    if isinstance(err, LaunchError) and str(path) in str(err):
        return err
    frames = [f for f in traceback.extract_tb(err.__traceback__) if Path(f.filename) == path]
    line = frames[-1].lineno if frames else 0
    what = str(err) if isinstance(err, LaunchError) else f"{type(err).__name__}: {err}"
    return LaunchError(f"{path}:{line}: {what}")


def test_runs(module: ModuleType, path: Path) -> list[TestRun]:
    """The launches of a test file: one, or one per value of ``launch_testing.parametrize``.

    Raises:
        LaunchError: no generate_test_description.
    """
    function = getattr(module, "generate_test_description", None)
    if callable(function) and getattr(function, "__parametrized__", False):
        return [TestRun(module, path, bound, values) for bound, values in function()]
    return [TestRun(module, path)]


class TestRun:
    """One launch of a test file: its description function, active and post-shutdown tests."""

    def __init__(
        self,
        module: ModuleType,
        path: Path,
        function: Callable[..., Any] | None = None,
        parameters: dict[str, Any] | None = None,
    ) -> None:
        function = function or getattr(module, "generate_test_description", None)
        if not callable(function):
            raise LaunchError(
                f"{path}: no generate_test_description() function; a launch test must define "
                "it and return a LaunchDescription with a launch_testing.actions.ReadyToTest()"
            )
        self.module = module
        self.path = path
        self.parameters = dict(parameters or {})
        shown = ", ".join(f"{k}={v}" for k, v in self.parameters.items())
        self.name = module.__name__ + (f"[{shown}]" if parameters is not None else "")
        self.function: Callable[..., Any] = function
        self.markers: dict[str, Any] = dict(getattr(function, "__markers__", {}))
        self.timeout = float(
            getattr(function, "__ready_to_test_action_timeout__", DEFAULT_READY_TIMEOUT)
        )
        self.pre_shutdown_tests = _loader(post_shutdown=False).loadTestsFromModule(module)
        self.post_shutdown_tests = _loader(post_shutdown=True).loadTestsFromModule(module)

    def describe(self, ready: Callable[[], None]) -> tuple[LaunchDescription, dict[str, Any]]:
        """Call generate_test_description; hand ``ready`` to its ReadyToTest action.

        Raises:
            LaunchError: it fails, returns no LaunchDescription, or has no ReadyToTest.
        """
        from rosl.launch.description import LaunchDescription
        from rosl.launch.testing.actions import ready_actions

        takes_ready_fn = "ready_fn" in inspect.signature(self.function).parameters
        try:
            result = self.function(ready_fn=ready) if takes_ready_fn else self.function()
        except unittest.SkipTest:
            raise
        except Exception as err:
            raise user_error(self.path, err) from None
        description, values = result if isinstance(result, tuple) else (result, {})
        if not isinstance(description, LaunchDescription) or not isinstance(values, dict):
            raise LaunchError(
                f"{self.path}: generate_test_description() returned {type(result).__name__}; "
                "it must return a LaunchDescription, or (LaunchDescription, dict)"
            )
        found = list(ready_actions(description.entities))
        if not found and not takes_ready_fn:
            raise LaunchError(
                f"{self.path}: generate_test_description() must return a LaunchDescription "
                "containing a launch_testing.actions.ReadyToTest() action"
            )
        for action in found:
            action._add_callback(ready)
        return description, values

    def bind(self, tests: unittest.TestSuite, values: dict[str, Any]) -> None:
        """Give ``values`` to the tests: by argument name, and as ``self.<name>`` attributes."""
        for cls in _classes(tests):
            for name in ("proc_info", "proc_output", "test_args", "launch_service"):
                if name in values:
                    setattr(cls, name, values[name])
            for hook in ("setUpClass", "tearDownClass"):
                setattr(cls, hook, _bound(getattr(cls, hook), values))
        for test in _tests(tests):
            for name in (test._testMethodName, "setUp", "tearDown"):
                setattr(test, name, _bound(getattr(test, name), values))

    def count(self) -> int:
        """How many tests the file holds."""
        return self.pre_shutdown_tests.countTestCases() + self.post_shutdown_tests.countTestCases()


def _loader(*, post_shutdown: bool) -> unittest.TestLoader:
    class Loader(unittest.TestLoader):
        def loadTestsFromTestCase(self, testCaseClass: type[unittest.TestCase]) -> Any:  # noqa: N802, N803
            if getattr(testCaseClass, "__post_shutdown_test__", False) != post_shutdown:
                return unittest.TestSuite()
            copy = type(testCaseClass.__name__, (testCaseClass,), {
                "__module__": testCaseClass.__module__,
                "__qualname__": testCaseClass.__qualname__,
            })  # fmt: skip
            return super().loadTestsFromTestCase(copy)

    return Loader()


def _bound(function: Callable[..., Any], values: dict[str, Any]) -> Callable[..., Any]:
    try:
        parameters = inspect.signature(function).parameters
    except (TypeError, ValueError):
        return function
    matching = {k: v for k, v in values.items() if k in parameters}
    return functools.partial(function, **matching) if matching else function


def _tests(suite: Any) -> Iterator[unittest.TestCase]:
    if isinstance(suite, unittest.TestSuite):
        for test in suite:
            yield from _tests(test)
    elif isinstance(suite, unittest.TestCase):
        yield suite


def _classes(suite: unittest.TestSuite) -> list[type[unittest.TestCase]]:
    found: list[type[unittest.TestCase]] = []
    for test in _tests(suite):
        if type(test) not in found:
            found.append(type(test))
    return found
