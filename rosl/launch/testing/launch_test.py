"""``rosl launch_test FILE [name:=value ...]``: ROS 2's ``launch_test`` on rosl's launcher.

The output is the launch's own (``[INFO] [talker-1]: process started ...``) and unittest's
verbose results, first of the active tests, then of the post-shutdown tests; the exit status
is 0 when every test passed, 1 otherwise (130 after Ctrl-C).
"""

from __future__ import annotations

import unittest
from typing import TYPE_CHECKING

from rosl.launch.testing.loader import TestRun, load_test_module

if TYPE_CHECKING:
    from pathlib import Path


def main(
    path: Path,
    arguments: dict[str, str],
    *,
    show_args: bool = False,
    package_name: str | None = None,
) -> int:
    """Run (or, with ``show_args``, describe the arguments of) one launch test file.

    Raises:
        LaunchError: the file is missing or is not a launch test (one line says why).
    """
    from rosl.launch.testing.test_runner import LaunchTestRunner

    module = load_test_module(path, package_name)
    test_run = TestRun(module, path.expanduser().resolve())
    if show_args:
        from rosl.launch.runner import argument_lines

        description, _ = test_run.describe(lambda: None)
        print("\n".join(argument_lines(description)))
        return 0
    try:
        result = LaunchTestRunner(test_run, arguments).run()
    except unittest.SkipTest as skipped:
        print(f"{test_run.name} is skipped: {skipped}")
        return 0
    if result.interrupted:
        return 130
    return 0 if result.wasSuccessful() else 1
