"""launch.events.process: the events aimed at processes, their matchers, and ``ProcessIO``."""

from rosl.compat.unsupported import unsupported_names
from rosl.launch.event_handlers import ProcessIO
from rosl.launch.events import (
    ProcessTargetedEvent,
    ShutdownProcess,
    SignalProcess,
    matches_executable,
    matches_name,
    matches_pid,
)

__all__ = [
    "ProcessIO",
    "ProcessTargetedEvent",
    "ShutdownProcess",
    "SignalProcess",
    "matches_executable",
    "matches_name",
    "matches_pid",
]
__getattr__ = unsupported_names("launch.events.process", __all__)
