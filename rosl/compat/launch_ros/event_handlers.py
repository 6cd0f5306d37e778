"""launch_ros.event_handlers: OnStateTransition needs lifecycle nodes, which rosl has not."""

from typing import Any

from rosl.launch.ros_actions import refuse_lifecycle

__all__: list[str] = []


def __getattr__(name: str) -> Any:
    if name.startswith("__"):
        raise AttributeError(name)
    raise refuse_lifecycle("launch_ros.event_handlers", name)
