"""``rosl pkg``: create, list, prefix, xml and executables, as ``ros2 pkg`` does them."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING

import pytest

from tests.cli.conftest import Result, assert_user_error
from tests.conftest import write_package

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path


@pytest.fixture
def created(workspace: Path, rosl: Callable[..., Result], monkeypatch: pytest.MonkeyPatch):
    """``pkg create demo_pkg --dependencies rclpy std_msgs geometry_msgs --node-name talker``,
    run from the workspace's src/ (as the ROS 2 tutorials do); the cwd is then the workspace."""
    monkeypatch.chdir(workspace / "src")
    result = rosl(
        "pkg", "create", "demo_pkg",
        "--dependencies", "rclpy", "std_msgs", "geometry_msgs",
        "--node-name", "talker",
        "--maintainer-name", "Ada", "--maintainer-email", "ada@example.com",
    )  # fmt: skip
    monkeypatch.chdir(workspace)
    return result, workspace / "src" / "demo_pkg"


def test_pkg_create_prints_the_ros2_summary_and_what_it_creates(created, workspace) -> None:
    result, _ = created
    assert result.code == 0, result.err
    assert result.err == ""
    lines = result.out.splitlines()
    assert lines[:11] == [
        "going to create a new package",
        "package name: demo_pkg",
        f"destination directory: {(workspace / 'src').resolve()}",
        "package format: 3",
        "version: 0.0.0",
        "description: TODO: Package description",
        "maintainer: ['Ada <ada@example.com>']",
        "licenses: ['TODO: License declaration']",
        "build type: ament_python",
        "dependencies: ['rclpy', 'std_msgs', 'geometry_msgs']",
        "node_name: talker",
    ]
    assert lines[11:] == [
        "creating folder ./demo_pkg",
        "creating ./demo_pkg/package.xml",
        "creating folder ./demo_pkg/demo_pkg",
        "creating ./demo_pkg/demo_pkg/__init__.py",
        "creating ./demo_pkg/demo_pkg/talker.py",
        "creating folder ./demo_pkg/msg",
        "creating folder ./demo_pkg/srv",
        "creating folder ./demo_pkg/launch",
    ]


def test_pkg_create_writes_a_well_formed_package_xml(created) -> None:
    _, folder = created
    root = ET.parse(folder / "package.xml").getroot()
    assert root.tag == "package"
    assert root.get("format") == "3"
    assert root.findtext("name") == "demo_pkg"
    assert root.findtext("version") == "0.0.0"
    assert [e.text for e in root.iter("depend")] == ["rclpy", "std_msgs", "geometry_msgs"]
    maintainer = root.find("maintainer")
    assert maintainer is not None
    assert maintainer.text == "Ada"
    assert maintainer.get("email") == "ada@example.com"
    assert root.findtext("export/build_type") == "ament_python"
    executables = root.findall("export/rosl/executable")
    assert [(e.get("name"), e.text) for e in executables] == [("talker", "demo_pkg.talker:main")]


def test_pkg_create_writes_the_folders_and_the_node_module(created) -> None:
    _, folder = created
    for sub in ("msg", "srv", "launch", "demo_pkg"):
        assert (folder / sub).is_dir(), sub
    assert (folder / "demo_pkg" / "__init__.py").read_text() == ""
    node = (folder / "demo_pkg" / "talker.py").read_text()
    compile(node, "talker.py", "exec")
    assert "def main(" in node
    assert 'super().__init__("talker")' in node


def test_pkg_list_contains_the_new_package(created, rosl) -> None:
    result = rosl("pkg", "list")
    assert result.code == 0
    names = result.out.splitlines()
    assert "demo_pkg" in names
    assert "std_msgs" in names
    assert names == sorted(names)


def test_pkg_prefix_prints_the_package_folder(created, rosl) -> None:
    _, folder = created
    result = rosl("pkg", "prefix", "demo_pkg")
    assert result.code == 0
    assert result.out == f"{folder.resolve()}\n"


def test_pkg_xml_prints_the_manifest(created, rosl) -> None:
    _, folder = created
    result = rosl("pkg", "xml", "demo_pkg")
    assert result.code == 0
    assert result.out == (folder / "package.xml").read_text()


def test_pkg_xml_with_a_tag_prints_each_value_on_a_line(created, rosl) -> None:
    assert rosl("pkg", "xml", "demo_pkg", "-t", "depend").out == (
        "rclpy\nstd_msgs\ngeometry_msgs\n"
    )
    assert rosl("pkg", "xml", "demo_pkg", "--tag", "version").out == "0.0.0\n"


def test_pkg_xml_with_a_missing_tag_is_one_line(created, rosl) -> None:
    assert_user_error(rosl("pkg", "xml", "demo_pkg", "-t", "url"), "<url>")


def test_pkg_executables_prints_package_and_executable(created, rosl) -> None:
    result = rosl("pkg", "executables", "demo_pkg")
    assert result.code == 0
    assert result.out == "demo_pkg talker\n"


def test_pkg_executables_full_path_prints_the_file(created, rosl) -> None:
    _, folder = created
    result = rosl("pkg", "executables", "demo_pkg", "--full-path")
    assert result.code == 0
    assert result.out == f"{(folder / 'demo_pkg' / 'talker.py').resolve()}\n"


def test_pkg_executables_without_a_package_lists_every_package(created, rosl) -> None:
    _, folder = created
    plain = rosl("pkg", "executables")
    assert plain.code == 0
    assert "demo_pkg talker" in plain.out.splitlines()
    full = rosl("pkg", "executables", "--full-path")
    assert str((folder / "demo_pkg" / "talker.py").resolve()) in full.out.splitlines()


def test_pkg_create_then_list_works_as_real_processes(
    workspace: Path, rosl_process: Callable[..., Result]
) -> None:
    made = rosl_process("pkg", "create", "proc_pkg", "--node-name", "n", cwd=workspace / "src")
    assert made.code == 0, made.err
    assert "dependencies: []" in made.out.splitlines()
    listed = rosl_process("pkg", "executables", "proc_pkg", cwd=workspace)
    assert listed.code == 0, listed.err
    assert listed.out == "proc_pkg n\n"


def test_pkg_create_without_a_node_writes_no_executable(
    workspace: Path, rosl: Callable[..., Result]
) -> None:
    result = rosl("pkg", "create", "bare_pkg", "--destination-directory", "src")
    assert result.code == 0, result.err
    folder = workspace / "src" / "bare_pkg"
    assert sorted(p.name for p in (folder / "bare_pkg").iterdir()) == ["__init__.py"]
    assert ET.parse(folder / "package.xml").getroot().findall("export/rosl/executable") == []
    assert "node_name" not in result.out
    assert rosl("pkg", "executables", "bare_pkg").out == ""


def test_pkg_create_ament_cmake_works_and_notes_it_on_stderr(
    workspace: Path, rosl: Callable[..., Result]
) -> None:
    result = rosl(
        "pkg", "create", "cmake_pkg", "--build-type", "ament_cmake",
        "--destination-directory", "src",
    )  # fmt: skip
    assert result.code == 0
    assert "build type: ament_cmake" in result.out.splitlines()
    assert len(result.err.splitlines()) == 1
    assert "ament_cmake" in result.err
    root = ET.parse(workspace / "src" / "cmake_pkg" / "package.xml").getroot()
    assert root.findtext("export/build_type") == "ament_cmake"
    assert "cmake_pkg" in rosl("pkg", "list").out.splitlines()


def test_pkg_create_over_an_existing_folder_aborts_and_leaves_it_untouched(
    workspace: Path, rosl_process: Callable[..., Result]
) -> None:
    existing = workspace / "src" / "taken"
    existing.mkdir()
    (existing / "notes.txt").write_text("mine\n")
    result = rosl_process("pkg", "create", "taken", cwd=workspace / "src")
    line = assert_user_error(result, "Aborted! The directory already exists")
    assert str(existing.resolve()) in line
    assert sorted(p.name for p in existing.iterdir()) == ["notes.txt"]
    assert (existing / "notes.txt").read_text() == "mine\n"
    assert "creating" not in result.out


@pytest.mark.parametrize("name", ["Bad-Name", "1pkg", "double__underscore", "trailing_"])
def test_pkg_create_refuses_an_invalid_name(
    workspace: Path, rosl: Callable[..., Result], name: str
) -> None:
    result = rosl("pkg", "create", name, "--destination-directory", "src")
    assert_user_error(result, f"invalid package name '{name}'")
    assert not (workspace / "src" / name).exists()
    assert result.out == ""


def test_pkg_create_refuses_an_invalid_node_name(
    workspace: Path, rosl: Callable[..., Result]
) -> None:
    result = rosl("pkg", "create", "ok_pkg", "--node-name", "Bad-Node")
    assert_user_error(result, "invalid node name 'Bad-Node'")
    assert not (workspace / "ok_pkg").exists()


def test_pkg_list_verbose_shows_the_shadowed_package(
    tmp_path: Path,
    make_package: Callable[..., Path],
    rosl: Callable[..., Result],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    mine = make_package("twin_pkg")
    other = write_package(tmp_path / "extra", "twin_pkg")
    monkeypatch.setenv("ROSL_PACKAGE_PATH", str(tmp_path / "extra"))
    result = rosl("pkg", "list", "--verbose")
    assert result.code == 0
    lines = result.out.splitlines()
    assert f"twin_pkg  {mine.resolve()}  (workspace)" in lines
    assert f"twin_pkg  {other.resolve()}  (shadowed by {mine.resolve()})" in lines
    assert rosl("pkg", "list").out.splitlines().count("twin_pkg") == 1


def test_pkg_list_with_a_broken_package_xml_lists_the_rest_and_warns(
    make_package: Callable[..., Path], rosl_process: Callable[..., Result], workspace: Path
) -> None:
    make_package("good_pkg")
    make_package("bad_pkg", manifest="<package><name>bad_pkg</name>\n")
    result = rosl_process("pkg", "list", cwd=workspace)
    assert result.code == 1
    assert "good_pkg" in result.out.splitlines()
    assert "std_msgs" in result.out.splitlines()
    assert "bad_pkg" not in result.out
    assert len(result.err_lines) == 1, result.err
    assert result.err_lines[0].startswith("warning: src/bad_pkg/package.xml:")
    assert "Traceback" not in result.err


@pytest.mark.parametrize("verb", ["prefix", "xml", "executables"])
def test_an_unknown_package_is_one_line_naming_it(
    workspace: Path, rosl: Callable[..., Result], verb: str
) -> None:
    assert_user_error(rosl("pkg", verb, "no_such_pkg"), "package 'no_such_pkg' not found")


def test_an_unknown_package_from_the_real_command_is_one_line(
    workspace: Path, rosl_process: Callable[..., Result]
) -> None:
    line = assert_user_error(
        rosl_process("pkg", "prefix", "std_msg", cwd=workspace), "package 'std_msg' not found"
    )
    assert "did you mean 'std_msgs'" in line


def test_ament_python_console_scripts_are_the_executables_without_a_rosl_block(
    make_package: Callable[..., Path], rosl: Callable[..., Result]
) -> None:
    setup_py = (
        "from setuptools import setup\n\n"
        "setup(\n"
        "    name='demo_py',\n"
        "    packages=['demo_py'],\n"
        "    entry_points={'console_scripts': ['talker = demo_py.talker:main']},\n"
        ")\n"
    )
    manifest = (
        '<?xml version="1.0"?>\n<package format="3">\n  <name>demo_py</name>\n'
        "  <version>0.0.0</version>\n"
        "  <export><build_type>ament_python</build_type></export>\n</package>\n"
    )
    folder = make_package(
        "demo_py",
        {"setup.py": setup_py, "demo_py/__init__.py": "", "demo_py/talker.py": "def main(): ..."},
        manifest=manifest,
    )
    result = rosl("pkg", "executables", "demo_py")
    assert result.code == 0
    assert result.out == "demo_py talker\n"
    full = rosl("pkg", "executables", "demo_py", "--full-path")
    assert full.out == f"{(folder / 'demo_py' / 'talker.py').resolve()}\n"


def test_ament_python_setup_cfg_console_scripts_are_read_too(
    make_package: Callable[..., Path], rosl: Callable[..., Result]
) -> None:
    setup_cfg = "[options.entry_points]\nconsole_scripts =\n    listener = cfg_py.listener:main\n"
    make_package("cfg_py", {"setup.cfg": setup_cfg, "cfg_py/__init__.py": ""})
    assert rosl("pkg", "executables", "cfg_py").out == "cfg_py listener\n"
