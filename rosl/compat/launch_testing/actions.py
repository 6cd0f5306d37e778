"""launch_testing.actions (rosl.launch.testing.actions implements it; no logic here)."""

from rosl.launch.testing.actions import (
    ReadyToTest,
)

__all__ = [
    "ReadyToTest",
]
