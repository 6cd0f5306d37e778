"""launch_testing.io_handler (rosl.launch.testing.io_handler implements it; no logic here)."""

from rosl.launch.testing.io_handler import (
    ActiveIoHandler,
    IoHandler,
    ProcessIO,
)

__all__ = [
    "ActiveIoHandler",
    "IoHandler",
    "ProcessIO",
]
