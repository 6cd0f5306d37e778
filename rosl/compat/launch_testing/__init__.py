"""``import launch_testing`` under rosl (rosl.launch.testing implements it; no logic here)."""

from rosl.launch.testing import __getattr__, post_shutdown_test, ready_to_test_action_timeout

__all__ = ["__getattr__", "post_shutdown_test", "ready_to_test_action_timeout"]
