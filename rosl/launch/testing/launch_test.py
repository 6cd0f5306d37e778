"""``rosl launch_test FILE [name:=value ...]``: ROS 2's ``launch_test`` on rosl's launcher.

The output is the launch's own (``[INFO] [talker-1]: process started ...``) and unittest's
verbose results, first of the active tests, then of the post-shutdown tests, for each launch of
the file (one, or one per value of ``launch_testing.parametrize``); the exit status is 0 when
every test passed, 1 otherwise (130 after Ctrl-C). ``junit_xml`` writes launch_testing's
JUnit report (colcon passes ``--junit-xml``); ``verbose`` prints what is being done.
"""

from __future__ import annotations

import unittest
from typing import TYPE_CHECKING

from rosl.launch.testing.loader import load_test_module, test_runs

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.launch.testing.test_runner import RunResult


def _debug(verbose: bool, text: str) -> None:
    if verbose:
        print(f"[DEBUG] [launch_test]: {text}", flush=True)


def main(
    path: Path,
    arguments: dict[str, str],
    *,
    show_args: bool = False,
    package_name: str | None = None,
    verbose: bool = False,
    junit_xml: Path | None = None,
) -> int:
    """Run (or, with ``show_args``, describe the arguments of) one launch test file.

    Raises:
        LaunchError: the file is missing or is not a launch test (one line says why).
    """
    from rosl.launch.testing.test_runner import LaunchTestRunner

    path = path.expanduser().resolve()
    base = path.name.removesuffix(".py")
    package = package_name or base
    _debug(verbose, f"Loading tests from file '{path}'")
    module = load_test_module(path, package_name)
    runs = test_runs(module, path)
    if show_args:
        from rosl.launch.runner import argument_lines

        description, _ = runs[0].describe(lambda: None)
        print("\n".join(argument_lines(description)))
        return 0
    results: list[tuple[str, RunResult]] = []
    for test_run in runs:
        _debug(verbose, f"Running integration test {test_run.name}")
        try:
            result = LaunchTestRunner(test_run, arguments).run()
        except unittest.SkipTest as skipped:
            print(f"{test_run.name} is skipped: {skipped}")
            continue
        _debug(verbose, f"Done running integration test {test_run.name}")
        suffix = test_run.name.removeprefix(module.__name__)
        results.append((f"{package}.{base}.launch_tests{suffix}", result))
        if result.interrupted:
            return 130
    if junit_xml is not None:
        from rosl.launch.testing.junitxml import write_report

        write_report(junit_xml, f"{package}.{base}", results)
        _debug(verbose, f"Wrote the JUnit report to {junit_xml}")
    return 0 if all(result.wasSuccessful() for _, result in results) else 1
