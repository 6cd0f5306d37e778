"""launch_testing.markers (rosl.launch.testing.markers implements it; no logic here)."""

from rosl.launch.testing.markers import (
    keep_alive,
    retry_on_failure,
)

__all__ = [
    "keep_alive",
    "retry_on_failure",
]
