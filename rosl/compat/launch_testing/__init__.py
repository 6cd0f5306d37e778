"""``import launch_testing`` under rosl (rosl.launch.testing implements it; no logic here)."""

import importlib
from typing import Any

from rosl.launch.testing import __getattr__ as _testing_getattr
from rosl.launch.testing import post_shutdown_test, ready_to_test_action_timeout

__all__ = ["post_shutdown_test", "ready_to_test_action_timeout"]


def __getattr__(name: str) -> Any:
    if name == "tools":  # this package's tools module: rosl's pieces of it in one place
        return importlib.import_module("launch_testing.tools")
    return _testing_getattr(name)
