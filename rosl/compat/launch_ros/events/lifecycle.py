"""launch_ros.events.lifecycle: ChangeState and friends need lifecycle nodes (not in rosl)."""

from typing import Any

from rosl.launch.ros_actions import refuse_lifecycle

__all__: list[str] = []


def __getattr__(name: str) -> Any:
    if name.startswith("__"):
        raise AttributeError(name)
    raise refuse_lifecycle("launch_ros.events.lifecycle", name)
