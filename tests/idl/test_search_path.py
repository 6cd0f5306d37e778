"""The search path: where the workspace is, which packages are found, in what order."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import pytest

from rosl.idl import search_path
from rosl.idl.errors import InterfaceError
from tests.conftest import REPO, write_package

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

SHIPPED = REPO / "interfaces"


def _names(cwd: Path | None = None) -> set[str]:
    search_path.rescan()
    return set(search_path.scan(cwd).packages)


# --- workspace discovery ---------------------------------------------------------------------


def test_the_workspace_is_found_from_its_own_folder(workspace: Path) -> None:
    assert search_path.find_workspace() == workspace.resolve()


def test_the_workspace_is_found_from_a_folder_deep_inside_a_package(
    workspace: Path, make_package: Callable[..., Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    pkg = make_package("deep_pkg", {"msg/Point2.msg": "float64 x\n"})
    monkeypatch.chdir(pkg / "msg")
    assert search_path.find_workspace() == workspace.resolve()
    assert "deep_pkg" in _names()


def test_a_packages_own_src_folder_is_not_taken_for_a_workspace(
    workspace: Path, make_package: Callable[..., Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    pkg = make_package("cpp_style", {"src/main.cpp": "int main() {}\n"})
    monkeypatch.chdir(pkg)
    assert search_path.find_workspace() == workspace.resolve()
    monkeypatch.chdir(pkg / "src")
    assert search_path.find_workspace() == workspace.resolve()
    roots = [root for root, origin, _ in search_path.search_roots() if origin == "workspace"]
    assert roots == [(workspace / "src").resolve()]


def test_the_workspace_search_root_is_its_src_folder(
    workspace: Path, make_package: Callable[..., Path]
) -> None:
    make_package("alpha_pkg")
    location = search_path.find_package("alpha_pkg")
    assert location.origin == "workspace"
    assert location.root == (workspace / "src").resolve()
    assert location.path == (workspace / "src" / "alpha_pkg").resolve()
    assert location.manifest == location.path / "package.xml"


def test_packages_in_nested_folders_of_src_are_found(workspace: Path) -> None:
    write_package(workspace / "src" / "group" / "sub", "nested_pkg")
    assert "nested_pkg" in _names()


# --- no workspace ------------------------------------------------------------------------------


def test_without_a_workspace_packages_directly_below_the_cwd_are_found(tmp_path: Path) -> None:
    here = tmp_path / "cwd"
    write_package(here, "below_pkg")
    write_package(here / "group", "too_deep_pkg")
    assert search_path.find_workspace() is None
    names = _names()
    assert "below_pkg" in names
    assert "too_deep_pkg" not in names


def test_without_a_workspace_the_package_enclosing_the_cwd_is_found(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pkg = write_package(tmp_path / "cwd", "enclosing_pkg", {"msg/Thing.msg": "int32 a\n"})
    monkeypatch.chdir(pkg / "msg")
    assert search_path.find_workspace() is None
    location = search_path.find_package("enclosing_pkg")
    assert location.path == pkg.resolve()
    assert location.origin == "workspace"


def test_without_a_workspace_a_sibling_of_the_enclosing_package_is_not_found(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    here = tmp_path / "cwd"
    pkg = write_package(here, "inside_pkg")
    write_package(here, "sibling_pkg")
    monkeypatch.chdir(pkg)
    names = _names()
    assert "inside_pkg" in names
    assert "sibling_pkg" not in names


# --- order and shadowing ----------------------------------------------------------------------


def test_a_workspace_package_shadows_one_of_the_same_name_on_rosl_package_path(
    tmp_path: Path, make_package: Callable[..., Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    mine = make_package("twin_pkg")
    extra = tmp_path / "extra"
    other = write_package(extra, "twin_pkg")
    monkeypatch.setenv("ROSL_PACKAGE_PATH", str(extra))
    search_path.rescan()
    result = search_path.scan()
    assert result.packages["twin_pkg"].path == mine.resolve()
    assert result.packages["twin_pkg"].origin == "workspace"
    hidden = [(h.path, w.path) for h, w in result.shadowed if h.name == "twin_pkg"]
    assert hidden == [(other.resolve(), mine.resolve())]


def test_rosl_package_path_entries_are_searched_in_order(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    first = write_package(tmp_path / "first", "dup_pkg")
    write_package(tmp_path / "second", "dup_pkg")
    write_package(tmp_path / "second", "only_second_pkg")
    monkeypatch.setenv(
        "ROSL_PACKAGE_PATH", os.pathsep.join([str(tmp_path / "first"), str(tmp_path / "second")])
    )
    search_path.rescan()
    result = search_path.scan()
    assert result.packages["dup_pkg"].path == first.resolve()
    assert result.packages["dup_pkg"].origin == "ROSL_PACKAGE_PATH"
    assert "only_second_pkg" in result.packages


def test_shipped_packages_are_found_and_come_last() -> None:
    result = search_path.scan()
    assert result.packages["std_msgs"].path == (SHIPPED / "std_msgs").resolve()
    assert result.packages["std_msgs"].origin == "shipped"
    origins = [origin for _, origin, _ in result.roots]
    assert origins[-1] == "shipped"
    assert origins.index("shipped") > origins.index("workspace")


def test_a_workspace_std_msgs_shadows_the_shipped_one(
    make_package: Callable[..., Path],
) -> None:
    mine = make_package("std_msgs", {"msg/Mine.msg": "int32 a\n"})
    result = search_path.scan()
    assert result.packages["std_msgs"].path == mine.resolve()
    hidden = [(h.path, w.path) for h, w in result.shadowed if h.name == "std_msgs"]
    assert hidden == [((SHIPPED / "std_msgs").resolve(), mine.resolve())]


def test_the_package_name_comes_from_package_xml_not_the_folder(
    make_package: Callable[..., Path],
) -> None:
    manifest = '<?xml version="1.0"?>\n<package format="3"><name>real_name</name></package>\n'
    folder = make_package("folder_name", manifest=manifest)
    names = _names()
    assert "real_name" in names
    assert "folder_name" not in names
    assert search_path.find_package("real_name").path == folder.resolve()


def test_rescan_picks_up_a_package_written_after_the_first_scan(workspace: Path) -> None:
    assert "late_pkg" not in search_path.scan().packages
    write_package(workspace / "src", "late_pkg")
    assert "late_pkg" not in search_path.scan().packages  # cached
    search_path.rescan()
    assert "late_pkg" in search_path.scan().packages


# --- broken manifests --------------------------------------------------------------------------


def test_a_package_xml_that_is_not_xml_is_listed_as_broken_with_its_location(
    make_package: Callable[..., Path],
) -> None:
    make_package("good_pkg")
    bad = make_package("bad_pkg", manifest='<?xml version="1.0"?>\n<package>\n  <name>bad_pkg\n')
    result = search_path.scan()
    assert "good_pkg" in result.packages
    assert "bad_pkg" not in result.packages
    assert len(result.broken) == 1
    err = result.broken[0]
    assert err.path == bad / "package.xml"
    assert err.line > 0
    assert err.col > 0
    text = str(err)
    assert text.startswith(f"src/bad_pkg/package.xml:{err.line}:{err.col}: ")
    assert "not well-formed XML" in text


def test_find_package_of_a_broken_package_raises_its_error(
    make_package: Callable[..., Path],
) -> None:
    make_package("bad_pkg", manifest="this is not xml at all\n")
    with pytest.raises(InterfaceError) as info:
        search_path.find_package("bad_pkg")
    assert "package.xml:1:1: package.xml is not well-formed XML" in str(info.value)


def test_a_package_xml_without_a_name_says_so_and_names_the_file(
    make_package: Callable[..., Path],
) -> None:
    folder = make_package("nameless", manifest='<?xml version="1.0"?>\n<package format="3"/>\n')
    result = search_path.scan()
    assert len(result.broken) == 1
    text = str(result.broken[0])
    assert "no <name>" in text
    assert "src/nameless/package.xml" in text
    with pytest.raises(InterfaceError, match="no <name>"):
        search_path.read_package_name(folder / "package.xml")


# --- unknown packages --------------------------------------------------------------------------


def test_an_unknown_package_error_names_it_suggests_a_close_name_and_lists_folders(
    workspace: Path,
) -> None:
    with pytest.raises(InterfaceError) as info:
        search_path.find_package("std_msg")
    text = str(info.value)
    assert "package 'std_msg' not found" in text
    assert "did you mean 'std_msgs'" in text
    assert str((workspace / "src").resolve()) in text
    assert str(SHIPPED.resolve()) in text
    assert "\n" not in text


def test_an_unknown_package_with_no_close_name_gets_no_suggestion() -> None:
    with pytest.raises(InterfaceError) as info:
        search_path.find_package("zzzqqq")
    assert "package 'zzzqqq' not found" in str(info.value)
    assert "did you mean" not in str(info.value)


# --- skipped folders ---------------------------------------------------------------------------


def test_a_folder_with_colcon_ignore_is_skipped(workspace: Path) -> None:
    write_package(workspace / "src" / "ignored", "ignored_pkg")
    (workspace / "src" / "ignored" / "COLCON_IGNORE").write_text("")
    write_package(workspace / "src", "kept_pkg")
    names = _names()
    assert "kept_pkg" in names
    assert "ignored_pkg" not in names


def test_a_package_folder_with_colcon_ignore_is_skipped(workspace: Path) -> None:
    folder = write_package(workspace / "src", "ignored_pkg")
    (folder / "COLCON_IGNORE").write_text("")
    assert "ignored_pkg" not in _names()


def test_hidden_folders_are_skipped(workspace: Path) -> None:
    write_package(workspace / "src" / ".hidden", "hidden_inner_pkg")
    write_package(
        workspace / "src",
        ".hidden_pkg",
        manifest='<?xml version="1.0"?>\n<package format="3"><name>dot_pkg</name></package>\n',
    )
    write_package(workspace / "src", "visible_pkg")
    names = _names()
    assert "visible_pkg" in names
    assert "hidden_inner_pkg" not in names
    assert "dot_pkg" not in names


def test_build_install_and_log_folders_are_skipped(workspace: Path) -> None:
    for skipped in ("build", "install", "log"):
        write_package(workspace / "src" / skipped, f"{skipped}_copy_pkg")
    names = _names()
    assert not {"build_copy_pkg", "install_copy_pkg", "log_copy_pkg"} & names
