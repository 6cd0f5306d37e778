"""launch_testing.util (rosl.launch.testing.util implements it; no logic here)."""

from rosl.launch.testing.util import (
    NO_CMD_ARGS,
    KeepAliveProc,
    NoMatchingProcessException,
    resolveProcesses,
)

__all__ = [
    "NO_CMD_ARGS",
    "KeepAliveProc",
    "NoMatchingProcessException",
    "resolveProcesses",
]
