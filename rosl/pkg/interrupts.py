"""Ctrl-C for the programs rosl starts: never ignored, and held until rosl's entry can take it.

A SIGINT that reaches a Python program while its interpreter starts or its modules load ends
it with a traceback (``Fatal Python error: init_import_site``, ``KeyboardInterrupt``), and a
launch's Ctrl-C reaches its children at any moment, often just as they start. So ``rosl
launch`` and ``rosl run`` start rosl's own entry points (``python -m rosl.pkg.entry``,
``python -m rosl``) with SIGINT blocked (pending, not lost) and say so in the environment
(:data:`HELD`); the entry point lets it in with :func:`release` where a Ctrl-C means a quiet
exit 130 (or, once ``rosl.init`` ran, a clean shutdown). Every program they start gets
SIGINT's default disposition, never the ``SIG_IGN`` that a background job inherits.
"""

from __future__ import annotations

import contextlib
import os
import signal

HELD = "ROSL_SIGINT_HELD"  # set for a program started with SIGINT blocked
_ENTRY_MODULES = ("rosl.pkg.entry", "rosl")


def takes_held_sigint(cmd: list[str]) -> bool:
    """Whether ``cmd`` runs a rosl entry point (``python [-P] -m rosl[.pkg.entry]``)."""
    head = cmd[1:4]
    return any(
        word == "-m" and index + 1 < len(head) and head[index + 1] in _ENTRY_MODULES
        for index, word in enumerate(head)
    )


def child_environment(cmd: list[str], env: dict[str, str]) -> dict[str, str]:
    """``env`` for a program started with :func:`prepare_child` (``HELD`` set if it holds)."""
    env = {key: value for key, value in env.items() if key != HELD}
    if takes_held_sigint(cmd):
        env[HELD] = "1"
    return env


def prepare_child(hold: bool) -> None:
    """In a new process, just before exec: SIGINT's default disposition; blocked if ``hold``."""
    if hold:
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    with contextlib.suppress(ValueError, OSError):  # not the main thread: exec resets it anyway
        signal.signal(signal.SIGINT, signal.SIG_DFL)


def caught() -> None:
    """Say that a KeyboardInterrupt was caught, so that the exit status is the program's own.

    CPython notes a KeyboardInterrupt that leaves code run by ``exec()`` of a string (a
    dataclass or message class being built, say) and, even if the program caught it later,
    ends the process at exit by SIGINT (status -2) instead of with the program's status (130).
    The note is cleared by the next ``exec()`` of a string that ends normally: this one.
    """
    exec("None")


def release() -> None:
    """Let in a SIGINT held since this program started (a pending one raises here)."""
    if os.environ.pop(HELD, None) is not None:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
