"""``rosl run PKG EXECUTABLE [args] [--ros-args ...]``: start one executable of a package."""

from __future__ import annotations

import os
import shlex
import signal
import sys

import click

from rosl.cli.options import domain_option, export_domain
from rosl.pkg.executables import command_line, find_executable


@click.command(
    "run", context_settings={"ignore_unknown_options": True, "allow_interspersed_args": False}
)
@click.option("--prefix", default=None, help="Prefix command, e.g. 'python -m cProfile'")
@domain_option
@click.argument("package_name")
@click.argument("executable_name")
@click.argument("argv", nargs=-1, type=click.UNPROCESSED)
def command(
    prefix: str | None,
    domain_id: int | None,
    package_name: str,
    executable_name: str,
    argv: tuple[str, ...],
) -> None:
    """Run a package specific executable (no build, no sourcing)."""
    export_domain(domain_id)
    executable = find_executable(package_name, executable_name)
    cmd = [*(shlex.split(prefix) if prefix else []), *command_line(executable, list(argv))]
    sys.stdout.flush()
    sys.stderr.flush()
    _exec(cmd)


def _exec(cmd: list[str]) -> None:
    """Become ``cmd``: SIGINT at its default (even in a background job), held for rosl's entry."""
    from rosl.pkg import interrupts

    hold = interrupts.takes_held_sigint(cmd)
    os.environ.pop(interrupts.HELD, None)
    if hold:
        os.environ[interrupts.HELD] = "1"
    previous = signal.getsignal(signal.SIGINT)
    interrupts.prepare_child(hold)
    try:
        os.execvp(cmd[0], cmd)
    except OSError:
        os.environ.pop(interrupts.HELD, None)
        signal.signal(signal.SIGINT, previous if previous is not None else signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
        raise
