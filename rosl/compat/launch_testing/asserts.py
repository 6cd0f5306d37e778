"""launch_testing.asserts (rosl.launch.testing.asserts implements it; no logic here)."""

from rosl.launch.testing.asserts import (
    EXIT_OK,
    EXIT_SIGINT,
    EXIT_SIGKILL,
    EXIT_SIGQUIT,
    EXIT_SIGSEGV,
    NO_CMD_ARGS,
    SequentialTextChecker,
    assertDefaultStream,
    assertExitCodes,
    assertInStderr,
    assertInStdout,
    assertInStream,
    assertSequentialStdout,
)

__all__ = [
    "EXIT_OK",
    "EXIT_SIGINT",
    "EXIT_SIGKILL",
    "EXIT_SIGQUIT",
    "EXIT_SIGSEGV",
    "NO_CMD_ARGS",
    "SequentialTextChecker",
    "assertDefaultStream",
    "assertExitCodes",
    "assertInStderr",
    "assertInStdout",
    "assertInStream",
    "assertSequentialStdout",
]
