"""launch_testing.asserts: exit codes, output (anywhere, or in order) of the launched processes.

``process`` is an action, (part of) a process label such as ``'talker'``, or None for every
process; ``cmd_args`` picks among processes of one name. Expected output is a string, a
compiled regex, or a list of them that must appear in that order.
"""

from __future__ import annotations

import contextlib
import os
import re
from typing import TYPE_CHECKING, Any

from rosl.launch.testing.util import NO_CMD_ARGS, resolveProcesses

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

__unittest = True  # unittest leaves this module's frames out of failure tracebacks
# (explicit ``raise AssertionError``, not ``assert``: pytest rewrites rosl's asserts, as it
# rewrites every module of a package with a pytest11 entry point, and would change the texts)

EXIT_OK = 0
EXIT_SIGINT = 130
EXIT_SIGQUIT = 131
EXIT_SIGKILL = 137
EXIT_SIGSEGV = 139
_ANSI = re.compile(r"\x1b\[[0-9;?]*[ -/]*[@-~]")


def _text_match(expected: Any) -> Callable[[str], bool]:
    """A predicate for ``expected``: text, a regex, or a list of both found one after another."""
    if isinstance(expected, str) or hasattr(expected, "search"):
        parts = [expected]
    elif isinstance(expected, (list, tuple)) and expected:
        parts = list(expected)
    else:
        raise ValueError(f"unknown format for expected output: {expected!r}")

    def match(text: str) -> bool:
        text = text.replace(os.linesep, "\n").replace("\r\n", "\n")
        position = 0
        for part in parts:
            if isinstance(part, str):
                index = text.find(part, position)
                if index < 0:
                    return False
                position = index + len(part)
            else:
                found = part.search(text, position)
                if found is None:
                    return False
                position = found.end()
        return True

    return match


def assertInStream(  # noqa: N802 - launch_testing's name
    proc_output: Any,
    expected_output: Any,
    process: Any,
    cmd_args: Any = None,
    *,
    output_filter: Callable[[str], str] | None = None,
    strict_proc_matching: bool = True,
    strip_ansi_escape_sequences: bool = True,
    stream: str = "stderr",
) -> None:
    """Fail unless ``expected_output`` is in a process's ``stream`` ('stdout' or 'stderr')."""
    if stream not in ("stdout", "stderr"):
        raise ValueError("Invalid value for stream; must be 'stdout' or 'stderr'")
    if output_filter is not None and not callable(output_filter):
        raise ValueError("output_filter is not callable")
    actions = resolveProcesses(
        proc_output, process=process, cmd_args=cmd_args, strict_proc_matching=strict_proc_matching
    )
    match = _text_match(expected_output)
    fd = 1 if stream == "stdout" else 2
    for action in actions:
        text = "".join(
            io.text.decode("utf-8", "replace") for io in proc_output[action] if io.fd == fd
        )
        if strip_ansi_escape_sequences:
            text = _ANSI.sub("", text)
        if output_filter is not None:
            text = output_filter(text)
        if match(text):
            return
    names = ", ".join(sorted(proc_output.process_details(a)["name"] for a in actions))
    raise AssertionError(
        f"Did not find '{expected_output}' in the {stream} of any of the matching processes: "
        f"{names}"
    )


def assertInStdout(  # noqa: N802 - launch_testing's name
    proc_output: Any,
    expected_output: Any,
    process: Any,
    cmd_args: Any = None,
    *,
    output_filter: Callable[[str], str] | None = None,
    strict_proc_matching: bool = True,
    strip_ansi_escape_sequences: bool = True,
) -> None:
    """Fail unless ``expected_output`` is in the process's standard output."""
    assertInStream(
        proc_output, expected_output, process, cmd_args, output_filter=output_filter,
        strict_proc_matching=strict_proc_matching,
        strip_ansi_escape_sequences=strip_ansi_escape_sequences, stream="stdout",
    )  # fmt: skip


def assertInStderr(  # noqa: N802 - launch_testing's name
    proc_output: Any,
    expected_output: Any,
    process: Any,
    cmd_args: Any = None,
    *,
    output_filter: Callable[[str], str] | None = None,
    strict_proc_matching: bool = True,
    strip_ansi_escape_sequences: bool = True,
) -> None:
    """Fail unless ``expected_output`` is in the process's standard error (ROS 2's log lines)."""
    assertInStream(
        proc_output, expected_output, process, cmd_args, output_filter=output_filter,
        strict_proc_matching=strict_proc_matching,
        strip_ansi_escape_sequences=strip_ansi_escape_sequences, stream="stderr",
    )  # fmt: skip


def assertDefaultStream() -> str:  # noqa: N802 - launch_testing's name
    """The stream ``assertInStream`` and ``assertWaitFor`` search by default."""
    return "stderr"


def assertExitCodes(  # noqa: N802 - launch_testing's name
    proc_info: Any,
    allowable_exit_codes: list[int] | tuple[int, ...] = (EXIT_OK,),
    process: Any = None,
    cmd_args: Any = None,
    *,
    strict_proc_matching: bool = True,
) -> None:
    """Fail unless every chosen process (all by default) exited with an allowed code."""
    for code in allowable_exit_codes:
        if not isinstance(code, int):
            raise TypeError(f"Provided exit code {code!r} is not an int")
    actions = resolveProcesses(
        proc_info, process=process, cmd_args=cmd_args, strict_proc_matching=strict_proc_matching
    )
    for action in actions:
        info = proc_info[action]
        returncode = getattr(info, "returncode", None)
        if returncode is None:
            raise AssertionError(f"Proc {info.process_name} has not exited")
        if returncode not in allowable_exit_codes:
            raise AssertionError(f"Proc {info.process_name} exited with code {returncode}")


class SequentialTextChecker:
    """Checks that texts appear in order in one process's output (``assertSequentialStdout``)."""

    def __init__(self, output: list[str]) -> None:
        self._output = output
        self._array_index = 0  # the output entry the last match ended in
        self._substring_index = 0  # where in it

    def assertInText(self, msg: str) -> None:  # noqa: N802 - launch_testing's name
        """Same as ``assertInStdout``."""
        self.assertInStdout(msg)

    def assertInStdout(self, msg: str) -> None:  # noqa: N802 - launch_testing's name
        """Fail unless ``msg`` appears after the previous match."""
        start = self._substring_index
        for index in range(self._array_index, len(self._output)):
            found = self._output[index].find(msg, start)
            if found >= 0:
                self._array_index, self._substring_index = index, found + len(msg)
                return
            start = 0
        raise AssertionError(
            f"'{msg}' not found in sequence after previous match. "
            f"The output near the last matched line:\n{self._nearby()}"
        )

    def _nearby(self) -> str:
        return "".join(self._output[max(0, self._array_index - 2) : self._array_index + 3])


@contextlib.contextmanager
def assertSequentialStdout(  # noqa: N802 - launch_testing's name
    proc_output: Any, process: Any, cmd_args: Any = None
) -> Iterator[SequentialTextChecker]:
    """A checker whose ``assertInStdout(text)`` calls must match one process's output in order.

    The output is everything the process printed, stdout and stderr, in the order it was read.
    """
    action = resolveProcesses(
        proc_output, process=process, cmd_args=cmd_args, strict_proc_matching=True
    )[0]
    yield SequentialTextChecker([io.text.decode("utf-8", "replace") for io in proc_output[action]])


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
