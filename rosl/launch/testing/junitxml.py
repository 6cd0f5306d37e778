"""JUnit XML reports of launch tests (``rosl launch_test --junit-xml FILE``), as colcon reads them.

The shape launch_testing writes: one ``<testsuites name="PKG.FILE">`` with the totals, one
``<testsuite>`` per launch of the file (``PKG.FILE.launch_tests``, with ``[name=value]`` for a
parametrized one) holding its active and post-shutdown tests, and one ``<testcase classname=
name= time=>`` per test with a ``<failure>``, ``<error>`` or ``<skipped>`` carrying the
traceback as its ``message``. A launch that ended before its active tests did is one
``<error>`` testcase named after the problem.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.launch.testing.test_runner import RunResult


def _counts(results: list[Any]) -> tuple[int, int, int, int]:
    tests = sum(r.testsRun for r in results)
    failures = sum(len(r.failures) for r in results)
    errors = sum(len(r.errors) for r in results)
    skipped = sum(len(r.skipped) for r in results)
    return tests, failures, errors, skipped


def _case(result: Any, test: Any) -> ET.Element:
    case = ET.Element("testcase")
    case.set("classname", type(test).__name__)
    case.set("name", getattr(test, "_testMethodName", str(test)))
    case.set("time", str(round(getattr(result, "testTimes", {}).get(test, 0.0), 3)))
    for tag, entries in (("failure", result.failures), ("error", result.errors),
                         ("skipped", result.skipped)):  # fmt: skip
        for failed, text in entries:
            if failed is test:
                ET.SubElement(case, tag, message=text)
    return case


def suite(name: str, run: RunResult) -> ET.Element:
    """The ``<testsuite>`` of one launch."""
    tests, failures, errors, skipped = _counts(run.results)
    element = ET.Element("testsuite", name=name)
    if run.problem is not None:
        tests, errors = tests + 1, errors + 1
    element.set("tests", str(tests))
    element.set("failures", str(failures))
    element.set("errors", str(errors))
    element.set("skipped", str(skipped))
    total = sum(sum(getattr(r, "testTimes", {}).values()) for r in run.results)
    element.set("time", str(round(total, 3)))
    for result in run.results:
        for test in getattr(result, "testCases", []):
            element.append(_case(result, test))
    if run.problem is not None:
        case = ET.SubElement(element, "testcase", classname=name, name="launch", time="0.0")
        ET.SubElement(case, "error", message=run.problem)
    return element


def write_report(path: Path, name: str, runs: list[tuple[str, RunResult]]) -> None:
    """Write the report of a test file's launches to ``path`` (UTF-8, with a declaration).

    Args:
        path: the XML file to write.
        name: ``PKG.FILE``, the ``<testsuites>`` name.
        runs: (suite name, result) of each launch.

    Raises:
        LaunchError: the file cannot be written (one line naming it).
    """
    root = ET.Element("testsuites", name=name)
    suites = [suite(suite_name, run) for suite_name, run in runs]
    for key in ("tests", "failures", "errors"):
        root.set(key, str(sum(int(s.get(key, "0")) for s in suites)))
    root.extend(suites)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)
    except OSError as err:
        from rosl.launch.errors import LaunchError

        raise LaunchError(f"cannot write the JUnit report {path}: {err.strerror}") from None
