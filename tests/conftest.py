"""Fixtures shared by every test: an isolated search path and helpers to write packages."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from rosl.idl import registry, search_path

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

REPO = Path(__file__).resolve().parent.parent


@pytest.fixture(autouse=True)
def isolated_search_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """Run each test from an empty folder, with no ROSL_PACKAGE_PATH and fresh caches."""
    home = tmp_path / "cwd"
    home.mkdir()
    monkeypatch.chdir(home)
    monkeypatch.delenv("ROSL_PACKAGE_PATH", raising=False)
    registry.clear()
    yield
    registry.clear()


def write_package(
    root: Path, name: str, files: dict[str, str] | None = None, manifest: str | None = None
) -> Path:
    """Write a package folder ``root/name`` with a package.xml and the given files."""
    folder = root / name
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(
        manifest
        if manifest is not None
        else f'<?xml version="1.0"?>\n<package format="3">\n  <name>{name}</name>\n'
        "  <version>0.0.0</version>\n</package>\n"
    )
    for relative, text in (files or {}).items():
        path = folder / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return folder


@pytest.fixture
def workspace(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A ROS-style workspace (``ws/src``) that is the current directory."""
    ws = tmp_path / "ws"
    (ws / "src").mkdir(parents=True)
    monkeypatch.chdir(ws)
    search_path.rescan()
    return ws


@pytest.fixture
def make_package(workspace: Path) -> Callable[..., Path]:
    """Write a package into the workspace's src/ and drop cached scans."""

    def make(name: str, files: dict[str, str] | None = None, manifest: str | None = None) -> Path:
        folder = write_package(workspace / "src", name, files, manifest)
        registry.clear()
        return folder

    return make
