"""``rosl.testing``: golden-log tests that record a launch, compare, and regenerate."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from typing import TYPE_CHECKING

import pytest

from rosl.testing import assert_matches_golden, record_launch
from tests.bag.conftest import edit_field, mcap_messages, rewrite
from tests.conftest import lock_domain

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

TALKER = """
import sys
import time
import rosl
from rosl.idl.registry import get_message_class

rosl.init([])
node = rosl.create_node("talker")
String = get_message_class("std_msgs/msg/String")
publisher = node.create_publisher(String, "/chatter", 10)
publisher.wait_for_subscribers(1, 30.0)
time.sleep(0.2)
for index in range(3):
    publisher.publish(String(data=f"{sys.argv[1]} {index}"))
    time.sleep(0.05)
time.sleep(0.2)
rosl.shutdown()
"""
LAUNCH = """
import sys
from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, ExecuteProcess
from launch.substitutions import LaunchConfiguration


def generate_launch_description():
    talker = str(Path(__file__).with_name("talker.py"))
    return LaunchDescription([
        DeclareLaunchArgument("text", default_value="hello"),
        ExecuteProcess(cmd=[sys.executable, talker, LaunchConfiguration("text")], output="screen"),
    ])
"""


@pytest.fixture(scope="module")
def launch_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("launch")
    (folder / "talker.py").write_text(TALKER)
    path = folder / "talk.launch.py"
    path.write_text(LAUNCH)
    return path


@pytest.fixture(scope="module")
def bus_env() -> Iterator[dict[str, str]]:
    domain, lock = lock_domain()
    try:
        yield {"ROSL_DOMAIN_ID": str(domain)}
    finally:
        lock.close()


@pytest.fixture(scope="module")
def golden(launch_file, bus_env, tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("golden")
    run = record_launch(launch_file, output=folder / "first", duration=20, env=bus_env)
    assert_matches_golden(run, folder / "golden", regenerate=True)
    return folder / "golden"


@pytest.mark.slow
def test_a_golden_test_passes_when_the_launch_behaves_as_recorded(
    launch_file, bus_env, golden, tmp_path
):
    run = record_launch(launch_file, output=tmp_path / "run", duration=20, env=bus_env)
    heard = [m.data for m in mcap_messages(run, {"/chatter"})]
    log = (tmp_path / "run.log").read_text()
    assert heard == [m.data for m in mcap_messages(golden, {"/chatter"})], log
    result = assert_matches_golden(run, golden)
    assert result is not None
    assert result.summary() == "bags match: 3 messages on 1 topics"


@pytest.mark.slow
def test_a_golden_test_fails_with_the_differences_when_the_launch_changed(
    launch_file, bus_env, golden, tmp_path
):
    run = record_launch(
        launch_file, output=tmp_path / "run", arguments={"text": "bye"}, duration=20, env=bus_env
    )
    with pytest.raises(AssertionError) as failure:
        assert_matches_golden(run, golden)
    message = str(failure.value)
    assert "does not match the golden bag" in message
    assert "/chatter #0 data: 'hello 0' vs 'bye 0'" in message
    assert "bags differ: 3 difference(s)" in message
    assert "--rosl-regenerate-golden" in message


def test_a_missing_golden_bag_fails_and_says_how_to_create_it(scenario_bag, tmp_path):
    with pytest.raises(AssertionError, match="--rosl-regenerate-golden"):
        assert_matches_golden(scenario_bag, tmp_path / "golden")


def test_the_environment_variable_regenerates_the_golden_bag(scenario_bag, tmp_path, monkeypatch):
    golden = tmp_path / "golden"
    changed = rewrite(
        scenario_bag, tmp_path / "changed",
        lambda r: edit_field(r, lambda m: setattr(m, "data", "x")) if r.topic == "/chatter" else r,
    )  # fmt: skip
    assert_matches_golden(changed, golden, regenerate=True)
    with pytest.raises(AssertionError):
        assert_matches_golden(scenario_bag, golden)
    monkeypatch.setenv("ROSL_REGENERATE_GOLDEN", "1")
    assert assert_matches_golden(scenario_bag, golden) is None
    monkeypatch.delenv("ROSL_REGENERATE_GOLDEN")
    assert assert_matches_golden(scenario_bag, golden) is not None
    assert mcap_messages(golden) == mcap_messages(scenario_bag)


def test_the_pytest_flag_regenerates_the_golden_bag_a_test_compares_with(scenario_bag, tmp_path):
    golden = tmp_path / "golden" / "run.mcap"
    project = tmp_path / "project"
    project.mkdir()
    (project / "test_golden.py").write_text(
        textwrap.dedent(f"""
        from pathlib import Path
        from rosl.testing import assert_matches_golden

        def test_matches_golden():
            assert_matches_golden(Path({str(scenario_bag)!r}), Path({str(golden)!r}))
        """)
    )
    env = {k: v for k, v in os.environ.items() if k != "ROSL_REGENERATE_GOLDEN"}

    def pytest_run(*flags: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "pytest", "-q", "-p", "rosl.testing", "-p", "no:cacheprovider",
             "--rootdir", str(project), *flags, str(project)],
            capture_output=True, text=True, timeout=60, cwd=project, env=env,
        )  # fmt: skip

    first = pytest_run()
    assert first.returncode == 1
    assert "no golden bag at" in first.stdout
    second = pytest_run("--rosl-regenerate-golden")
    assert second.returncode == 0, second.stdout
    assert golden.is_file()
    third = pytest_run()
    assert third.returncode == 0, third.stdout
    assert "1 passed" in third.stdout
