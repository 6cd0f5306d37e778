"""The wheel carries the shipped data, and an installed rosl finds it (as an editable one does)."""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from tests.conftest import REPO

pytestmark = [pytest.mark.slow, pytest.mark.timeout(300)]

_IGNORE = shutil.ignore_patterns(
    ".venv", ".git", "build", "dist", "*.egg-info", "__pycache__", ".*_cache", ".hypothesis"
)


def _run(args: list[str], cwd: Path, timeout: float = 240) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        args, cwd=cwd, capture_output=True, text=True, timeout=timeout, check=False
    )


def _build_outputs() -> set[Path]:
    """What a build may leave in the checkout (an editable install's egg-info is already there)."""
    return {*REPO.glob("*.egg-info"), *REPO.glob("build"), *REPO.glob("dist")}


@pytest.fixture(scope="module")
def outputs_before_the_build() -> set[Path]:
    return _build_outputs()


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory, outputs_before_the_build: set[Path]) -> Path:
    """A wheel built from a copy of the checkout (the checkout itself is left as it is)."""
    base = tmp_path_factory.mktemp("packaging")
    source = base / "source"
    shutil.copytree(REPO, source, ignore=_IGNORE)
    dist = base / "dist"
    pip_wheel = [sys.executable, "-m", "pip", "wheel", "--no-deps", "-w", str(dist)]
    done = _run([*pip_wheel, "--no-build-isolation", str(source)], cwd=base)
    if done.returncode != 0:  # the venv's setuptools may be too old or lack bdist_wheel
        done = _run([*pip_wheel, str(source)], cwd=base)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    wheels = sorted(dist.glob("rosl-*.whl"))
    assert len(wheels) == 1, wheels
    return wheels[0]


@pytest.fixture(scope="module")
def wheel_names(wheel: Path) -> set[str]:
    with zipfile.ZipFile(wheel) as archive:
        return set(archive.namelist())


@pytest.fixture(scope="module")
def installed(wheel: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh venv (no system site packages) with only the wheel installed; its python."""
    venv = tmp_path_factory.mktemp("venv") / "env"
    made = _run([sys.executable, "-m", "venv", "--without-pip", str(venv)], cwd=venv.parent)
    assert made.returncode == 0, made.stderr
    python = venv / "bin" / "python"
    done = _run(
        [
            sys.executable, "-m", "pip", "--python", str(python),
            "install", "--no-deps", "--no-index", str(wheel),
        ],
        cwd=venv.parent,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return python


def test_building_the_wheel_leaves_no_build_output_in_the_checkout(
    wheel: Path, outputs_before_the_build: set[Path]
) -> None:
    assert wheel.is_file()
    assert _build_outputs() == outputs_before_the_build


def test_the_wheel_ships_the_interfaces(wheel_names: set[str]) -> None:
    assert "rosl/_data/interfaces/std_msgs/msg/String.msg" in wheel_names
    assert "rosl/_data/interfaces/geometry_msgs/msg/Twist.msg" in wheel_names
    assert "rosl/_data/interfaces/std_srvs/srv/Trigger.srv" in wheel_names


def test_the_wheel_ships_every_interface_file_of_the_checkout(wheel_names: set[str]) -> None:
    shipped = {
        f"rosl/_data/interfaces/{p.relative_to(REPO / 'interfaces').as_posix()}"
        for p in (REPO / "interfaces").rglob("*")
        if p.is_file() and "__pycache__" not in p.parts
    }
    assert shipped
    assert shipped - wheel_names == set()


@pytest.mark.parametrize("folder", ["worlds", "examples"])
def test_the_wheel_ships_the_worlds_and_examples_folders(
    wheel_names: set[str], folder: str
) -> None:
    files = [
        p.relative_to(REPO / folder).as_posix()
        for p in (REPO / folder).rglob("*")
        if p.is_file() and "__pycache__" not in p.parts
    ]
    expected = {f"rosl/_data/{folder}/{name}" for name in files}
    assert expected - wheel_names == set()
    if folder == "worlds":
        assert files, "the checkout ships at least one world"


def test_the_wheel_holds_every_module_of_the_rosl_package(wheel_names: set[str]) -> None:
    modules = {
        p.relative_to(REPO).as_posix()
        for p in (REPO / "rosl").rglob("*.py")
        if "__pycache__" not in p.parts
    }
    assert modules - wheel_names == set()


def test_the_wheel_declares_the_rosl_command(wheel: Path) -> None:
    with zipfile.ZipFile(wheel) as archive:
        entry_points = next(n for n in archive.namelist() if n.endswith("entry_points.txt"))
        text = archive.read(entry_points).decode()
    assert "rosl = rosl.cli.main:main" in text


def test_an_installed_rosl_finds_the_interfaces_inside_its_site_packages(
    installed: Path, tmp_path: Path
) -> None:
    done = _run(
        [
            str(installed), "-c",
            "from rosl.resources import shipped_dir; print(shipped_dir('interfaces'))",
        ],
        cwd=tmp_path,
        timeout=60,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    found = Path(done.stdout.strip())
    venv = installed.parent.parent
    assert found.is_relative_to(venv)
    assert "site-packages" in found.parts
    assert not found.is_relative_to(REPO)
    assert (found / "std_msgs" / "msg" / "String.msg").is_file()


def test_the_editable_install_finds_the_checkouts_interfaces(tmp_path: Path) -> None:
    done = _run(
        [
            sys.executable, "-c",
            "from rosl.resources import shipped_dir; print(shipped_dir('interfaces'))",
        ],
        cwd=tmp_path,
        timeout=60,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    assert Path(done.stdout.strip()) == (REPO / "interfaces").resolve()
