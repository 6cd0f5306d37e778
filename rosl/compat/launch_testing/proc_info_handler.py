"""launch_testing.proc_info_handler (implemented in rosl.launch.testing; no logic here)."""

from rosl.launch.testing.proc_info_handler import (
    ActiveProcInfoHandler,
    ProcessExited,
    ProcessStarted,
    ProcInfoHandler,
)

__all__ = [
    "ActiveProcInfoHandler",
    "ProcInfoHandler",
    "ProcessExited",
    "ProcessStarted",
]
