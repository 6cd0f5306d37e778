"""tf2 tests expect tf2_echo's Humble text: no ROS_DISTRO from the machine running them."""

from __future__ import annotations

import pytest


@pytest.fixture(autouse=True)
def humble_text(monkeypatch: pytest.MonkeyPatch) -> None:
    """Unset ROS_DISTRO here and in the processes the test starts."""
    monkeypatch.delenv("ROS_DISTRO", raising=False)
