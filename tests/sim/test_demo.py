"""The README's demo (``rosl launch rosl_sim demo.launch.py``): what it prints stays true."""

from __future__ import annotations

import subprocess
from typing import TYPE_CHECKING

import pytest

from tests.conftest import REPO
from tests.sim.conftest import raw_bag, read_bag

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

pytestmark = pytest.mark.slow

BURGER_MAX_LINEAR = 0.22  # worlds/robots/turtlebot3_burger.yaml
BURGER_MAX_ANGULAR = 2.84


@pytest.fixture
def demo_run(processes: Processes, tmp_path: Path) -> tuple[Path, str]:
    """Ten simulated seconds of the demo, run as the README says, in an empty folder."""
    folder = tmp_path / "here"
    folder.mkdir()
    child = processes.rosl(
        "launch", "rosl_sim", "demo.launch.py", "duration:=10", cwd=folder, env={"NO_COLOR": "1"}
    )
    out, err = child.communicate(timeout=180)
    assert child.returncode == 0, out[-3000:] + err[-3000:]
    return folder, out + err


def test_the_demos_controller_stays_within_the_burgers_limits(demo_run: tuple[Path, str]) -> None:
    folder, output = demo_run

    assert "simulated 10.00 s of turtlebot3_world" in output, output[-3000:]
    assert "clamped" not in output, output[-3000:]
    (bag,) = [p for p in folder.iterdir() if p.is_dir()]
    commands = [msg for _, _, msg in read_bag(bag, "/cmd_vel")]
    assert len(commands) > 10
    linear = [c.linear.x for c in commands]  # type: ignore[attr-defined]
    angular = [c.angular.z for c in commands]  # type: ignore[attr-defined]
    assert max(linear) == pytest.approx(BURGER_MAX_LINEAR)  # it did drive, at full speed
    assert all(abs(v) <= BURGER_MAX_LINEAR for v in linear)
    assert all(abs(w) <= BURGER_MAX_ANGULAR for w in angular)


def test_what_the_demo_leaves_in_the_folder_is_ignored_by_git(demo_run: tuple[Path, str]) -> None:
    folder, _ = demo_run
    written = sorted(p.name for p in folder.iterdir())
    assert len(written) == 2, written  # the bag folder and its picture
    bag, picture = (
        (written[0], written[1]) if (folder / written[0]).is_dir() else (written[1], written[0])
    )
    assert bag.startswith("demo_")
    assert picture == f"{bag}.png"
    inside = sorted(p.name for p in (folder / bag).iterdir())
    as_if_in_the_repo = [picture, *(f"{bag}/{name}" for name in inside)]

    checked = subprocess.run(
        ["git", "-C", str(REPO), "check-ignore", "--no-index", *as_if_in_the_repo],
        capture_output=True,
        text=True,
        timeout=30,
        check=False,
    )

    assert sorted(checked.stdout.splitlines()) == sorted(as_if_in_the_repo), checked


def test_two_lock_step_runs_of_the_demo_record_byte_identical_bags(
    processes: Processes, tmp_path: Path
) -> None:
    recorded = []
    for run in ("first", "second"):
        folder = tmp_path / run
        folder.mkdir()
        child = processes.rosl(
            "launch", "rosl_sim", "demo.launch.py", "duration:=4", "bag:=demo", cwd=folder,
            env={"NO_COLOR": "1"},
        )  # fmt: skip
        out, err = child.communicate(timeout=180)
        assert child.returncode == 0, out[-3000:] + err[-3000:]
        (mcap,) = (folder / "demo").glob("*.mcap")
        recorded.append(mcap.read_bytes())
        topics = {topic for topic, _, _ in raw_bag(folder / "demo")}
        assert {"/scan", "/odom", "/tf", "/clock", "/cmd_vel"} <= topics, topics

    assert recorded[0] == recorded[1]
