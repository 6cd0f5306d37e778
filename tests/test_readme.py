"""The README opens with the two commands, and CI runs the second one exactly."""

from __future__ import annotations

import re

from tests.conftest import REPO


def readme_commands() -> list[str]:
    text = (REPO / "README.md").read_text()
    return re.findall(r"```bash\n(.*?)\n```", text, flags=re.S)[:2]


def test_readme_opens_with_an_install_and_a_test_command():
    demo, tests = readme_commands()
    assert "pip install" in demo
    assert demo.endswith("rosl launch rosl_sim demo.launch.py")
    assert "pip install" in tests
    assert "pytest" in tests


def test_ci_runs_the_readme_test_command():
    ci = (REPO / ".ci" / "run").read_text().splitlines()
    assert readme_commands()[1] in ci
