"""``rosl viz``: RViz's picture of a recorded run or of the live system, as PNG or SVG."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import pytest

from tests.conftest import lock_domain
from tests.launch.support import one_error_line

if TYPE_CHECKING:
    from pathlib import Path

    from tests.launch.support import Rosl

pytestmark = pytest.mark.slow

RVIZ = """Panels:
  - Class: rviz_common/Displays
Visualization Manager:
  Class: ""
  Global Options:
    Background Color: 48; 48; 48
    Fixed Frame: {frame}
    Frame Rate: 30
  Name: root
"""


@pytest.fixture(scope="module")
def demo_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Ten simulated seconds of the README's demo, recorded (one run for the module)."""
    import os
    import subprocess
    import sys

    folder = tmp_path_factory.mktemp("viz")
    bag = folder / "run"
    domain, lock = lock_domain()
    env = {**os.environ, "ROSL_DOMAIN_ID": str(domain), "NO_COLOR": "1"}
    with lock:
        done = subprocess.run(
            [sys.executable, "-m", "rosl", "launch", "rosl_sim", "demo.launch.py",
             "duration:=10", f"bag:={bag}"],
            cwd=folder, env=env, capture_output=True, text=True, timeout=120, check=False,
        )  # fmt: skip
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert (bag / "metadata.yaml").is_file()
    return bag


@pytest.fixture(scope="module")
def dolly_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Three simulated seconds of Dolly in its field (no odom frame: odom_demo), recorded."""
    import os
    import subprocess
    import sys

    folder = tmp_path_factory.mktemp("dolly")
    bag = folder / "dolly"
    domain, lock = lock_domain()
    env = {**os.environ, "ROSL_DOMAIN_ID": str(domain), "NO_COLOR": "1"}
    with lock:
        done = subprocess.run(
            [sys.executable, "-m", "rosl", "sim", "dolly_field", "--headless", "--duration", "3",
             "--real-time-factor", "10", "--record", str(bag)],
            cwd=folder, env=env, capture_output=True, text=True, timeout=120, check=False,
        )  # fmt: skip
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert (bag / "metadata.yaml").is_file()
    return bag


def svg_counts(text: str) -> dict[str, int]:
    return {tag: len(re.findall(rf"<{tag}\b", text)) for tag in ("polyline", "circle", "line")}


def test_a_recorded_run_is_drawn_with_its_path_scan_and_frames_in_odom(
    rosl: Rosl, demo_bag: Path, tmp_path: Path
) -> None:
    out = tmp_path / "run.svg"
    code, stdout, err = rosl.run("viz", str(demo_bag), "-o", str(out), timeout=60)

    assert code == 0, err
    assert stdout.strip() == f"wrote {out}"
    text = out.read_text()
    assert "(fixed frame: odom)" in text
    counts = svg_counts(text)
    assert counts["polyline"] >= 1  # the odometry path
    assert counts["circle"] > 100  # the last scan's points (360 rays in a small arena)
    assert counts["line"] > 30  # the arena's walls and pillars' edges
    for label in ("odom", "/odom pose", "base_scan"):  # the fixed frame, the robot, the LiDAR
        assert f">{label}</text>" in text


def test_a_recorded_run_as_png_is_a_real_picture(
    rosl: Rosl, demo_bag: Path, tmp_path: Path
) -> None:
    from PIL import Image

    out = tmp_path / "run.png"
    code, _, err = rosl.run("viz", str(demo_bag), "-o", str(out), timeout=60)

    assert code == 0, err
    with Image.open(out) as image:
        assert image.format == "PNG"
        assert image.width >= 400
        histogram = image.convert("L").histogram()
        drawn = sum(histogram[:200])
    assert drawn > 2000  # walls, path and scan: not a blank page


def test_an_rviz_config_gives_its_fixed_frame_as_rviz2_d_does(
    rosl: Rosl, demo_bag: Path, tmp_path: Path
) -> None:
    config = tmp_path / "robot.rviz"
    config.write_text(RVIZ.format(frame="base_footprint"))
    out = tmp_path / "robot.svg"
    code, _, err = rosl.run("viz", str(demo_bag), "-d", str(config), "-o", str(out), timeout=60)

    assert code == 0, err
    assert "(fixed frame: base_footprint)" in out.read_text()
    # -f still wins over the config, as a command-line choice should
    code, _, err = rosl.run(
        "viz", str(demo_bag), "-d", str(config), "-f", "odom", "-o", str(out), timeout=60
    )
    assert code == 0, err
    assert "(fixed frame: odom)" in out.read_text()


@pytest.mark.parametrize(
    ("content", "message"),
    [
        ("not: [an rviz", "not an RViz config (not YAML)"),
        ("Panels: []\n", "not an RViz config (no 'Visualization Manager')"),
    ],
    ids=["not-yaml", "no-manager"],
)
def test_a_bad_rviz_config_is_one_line(
    rosl: Rosl, demo_bag: Path, tmp_path: Path, content: str, message: str
) -> None:
    config = tmp_path / "bad.rviz"
    config.write_text(content)
    code, out, err = rosl.run(
        "viz", str(demo_bag), "-d", str(config), "-o", str(tmp_path / "x.png")
    )

    assert code == 1
    assert out == ""
    assert one_error_line(err) == f"{config}: {message}"
    assert not (tmp_path / "x.png").exists()


def test_the_live_system_is_drawn_from_what_the_simulator_publishes(
    rosl: Rosl, tmp_path: Path
) -> None:
    sim = rosl.start("sim", "turtlebot3_world", "--headless")
    assert sim.wait_for(r"turtlebot3_world is up", stream="err", timeout=60.0), sim.both()
    out = tmp_path / "live.svg"
    code, _, err = rosl.run("viz", "-o", str(out), "--duration", "1.5", timeout=60)

    assert code == 0, err
    text = out.read_text()
    assert "live (fixed frame: odom)" in text
    assert svg_counts(text)["circle"] > 100  # a scan arrived within the wait
    assert ">/odom pose</text>" in text


DOLLY_NOTE = (
    "fixed frame: odom_demo (there is no 'odom' frame; odom_demo is the frame of /dolly/odom)"
)


def test_dollys_run_is_drawn_in_its_odometry_frame_when_there_is_no_odom(
    rosl: Rosl, dolly_bag: Path, tmp_path: Path
) -> None:
    out = tmp_path / "dolly.svg"
    code, stdout, err = rosl.run("viz", str(dolly_bag), "-o", str(out), timeout=60)

    assert code == 0, err
    assert stdout.splitlines() == [DOLLY_NOTE, f"wrote {out}"]
    text = out.read_text()
    assert "(fixed frame: odom_demo)" in text
    assert svg_counts(text)["circle"] > 50  # the last scan, placed through chassis -> odom_demo
    labels = re.findall(r'<text x="([\d.]+)" y="([\d.]+)"[^>]*font-size="11">([^<]+)</text>', text)
    assert sorted(name for _, _, name in labels) == ["/dolly/odom pose", "chassis", "odom_demo"]
    assert len({(x, y) for x, y, _ in labels}) == 3  # all at one spot, drawn at three places


def test_dollys_run_as_png_is_a_real_picture(rosl: Rosl, dolly_bag: Path, tmp_path: Path) -> None:
    from PIL import Image

    out = tmp_path / "dolly.png"
    code, stdout, err = rosl.run("viz", str(dolly_bag), "-o", str(out), timeout=60)

    assert code == 0, err
    assert stdout.splitlines()[0] == DOLLY_NOTE
    with Image.open(out) as image:
        assert image.format == "PNG"
        drawn = sum(image.convert("L").histogram()[:200])
    assert drawn > 2000  # the fence, the obstacles and the scan: not a blank page


def test_an_odom_fixed_frame_asked_for_on_dollys_run_is_still_an_error(
    rosl: Rosl, dolly_bag: Path, tmp_path: Path
) -> None:
    code, out, err = rosl.run(
        "viz", str(dolly_bag), "-f", "odom", "-o", str(tmp_path / "x.png"), timeout=60
    )

    assert code == 1
    assert out == ""
    assert one_error_line(err).startswith("fixed frame 'odom' is not in the TF tree")
