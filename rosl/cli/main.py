"""The ``rosl`` root command: a static, lazy map of command groups and the error boundary.

Subcommand modules are imported only when used, so ``rosl --help`` and ``rosl topic list``
never load numpy, pymunk or mcap. Errors: a ``RoslError`` prints one line on stderr and exits
1; click usage errors keep exit 2; Ctrl-C exits 130 quietly; anything else is a bug and keeps
its traceback. Run as the ``rosl`` script, the groups that only print and use the bus end
without the interpreter's teardown (atexit handlers run, streams are flushed).
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import threading
from typing import Any

import click

from rosl.errors import RoslError

# name -> (module, one-line help); the module defines a click command named ``command``
# (``module:name`` picks another attribute)
COMMANDS: dict[str, tuple[str, str]] = {
    "action": ("rosl.cli.action", "Various action related sub-commands"),
    "bag": ("rosl.cli.bag", "Various rosbag related sub-commands"),
    "bridge": ("rosl.cli.bridge", "Serve the live bus to Foxglove (foxglove_bridge)"),
    "component": ("rosl.cli.planned:component", "Components: not in rosl (C++ only)"),
    "daemon": ("rosl.cli.daemon", "rosl has no daemon: start/stop/status say so"),
    "doctor": ("rosl.cli.doctor", "Check the setup: multicast, domain, packages, graph"),
    "graph": ("rosl.cli.graph", "The node/topic graph as DOT, Mermaid or text (rqt_graph)"),
    "interface": ("rosl.cli.interface", "Show information about ROS interfaces"),
    "launch": ("rosl.cli.launch", "Run a launch file"),
    "launch_test": ("rosl.cli.launch_test", "Run a launch test (ROS 2's launch_test)"),
    "lifecycle": ("rosl.cli.lifecycle", "Various lifecycle related sub-commands"),
    "multicast": ("rosl.cli.multicast", "Various multicast related sub-commands"),
    "node": ("rosl.cli.node", "Various node related sub-commands"),
    "param": ("rosl.cli.param", "Various param related sub-commands"),
    "pkg": ("rosl.cli.pkg", "Various package related sub-commands"),
    "run": ("rosl.cli.run", "Run a package specific executable"),
    "service": ("rosl.cli.service", "Various service related sub-commands"),
    "sim": ("rosl.cli.sim", "Simulate a 2D world: TurtleBot3 or Dolly, LiDAR, odometry, /clock"),
    "tf": ("rosl.cli.tf", "TF frames: the tree (view_frames) and transforms (tf2_echo)"),
    "topic": ("rosl.cli.topic", "Various topic related sub-commands"),
    "viz": ("rosl.cli.viz", "Draw the world, paths, scans and frames from a bag or the bus"),
    "wtf": ("rosl.cli.doctor", "Use `wtf` as alias to `doctor`"),
    "zenoh": ("rosl.cli.zenoh", "Zenoh: a router for rosl and rmw_zenoh nodes (rmw_zenohd)"),
}
CONTEXT = {"help_option_names": ["-h", "--help"], "max_content_width": 100}


class LazyGroup(click.Group):
    """A group whose subcommands are imported on first use."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        """List the command names."""
        return sorted(COMMANDS)

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        """Import and return one command."""
        if cmd_name not in COMMANDS:
            return None
        module_name, _, attribute = COMMANDS[cmd_name][0].partition(":")
        module = importlib.import_module(module_name)
        command: click.Command = getattr(module, attribute or "command")
        return command

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """Write the command list without importing any command."""
        rows = [(name, COMMANDS[name][1]) for name in self.list_commands(ctx)]
        with formatter.section("Commands"):
            formatter.write_dl(rows)

    def resolve_command(
        self, ctx: click.Context, args: list[str]
    ) -> tuple[str | None, click.Command | None, list[str]]:
        """Resolve a command name, suggesting close names for typos."""
        name = args[0] if args else ""
        if name and not name.startswith("-") and name not in COMMANDS:
            from rosl.idl.names import did_you_mean

            ctx.fail(f"unknown command '{name}'{did_you_mean(name, COMMANDS)}")
        return super().resolve_command(ctx, args)


@click.group(cls=LazyGroup, context_settings=CONTEXT)
@click.version_option(package_name="rosl", prog_name="rosl")
def cli() -> None:
    """rosl: ROS 2's everyday workflow in pure Python: no ROS install, no build step."""


def main(argv: list[str] | None = None) -> int:
    """Run the command line and return (or exit with) its status."""
    _take_sigint()
    from rosl.pkg import interrupts

    leave = (argv if argv is not None else sys.argv[1:])[:1] in _LEAVE_AT_ONCE

    try:
        interrupts.release()  # a Ctrl-C held since start-up (a launch's helper) lands here: 130
        result: Any = cli.main(args=argv, prog_name="rosl", standalone_mode=False)
    except click.exceptions.Exit as done:
        return _exit(done.exit_code, leave)
    except click.ClickException as err:
        err.show()
        return _exit(err.exit_code, leave)
    except (click.exceptions.Abort, KeyboardInterrupt):
        interrupts.caught()  # 130, even if the Ctrl-C landed in a class being built
        return _exit(130, leave)
    except RoslError as err:
        _flush_quietly()
        print(str(err).splitlines()[0] if str(err) else type(err).__name__, file=sys.stderr)
        return _exit(err.exit_code, leave)
    except BrokenPipeError:
        _silence_stdout()
        return _exit(1, leave)
    code = result if isinstance(result, int) else 0
    signalled = _signalled()
    if signalled is not None and code == 0:  # stopped by Ctrl-C (rosl's first one is quiet)
        code = 128 + signalled
    _flush_quietly()
    return _exit(code, leave)


# the groups whose commands only print and use the bus: they end without the interpreter's
# teardown (10-20 ms of a ~100 ms command); a file they write is closed before they return
_LEAVE_AT_ONCE = [["topic"], ["node"], ["service"], ["action"], ["param"], ["interface"]]


def _as_script() -> bool:
    return __name__ == "__main__" or bool(sys.argv and sys.argv[0].endswith("rosl"))


def _leave(code: int) -> None:
    """Exit now: atexit handlers run and streams are flushed, the modules are not torn down.

    A normal exit instead while a non-daemon thread runs (a normal exit waits for it).
    """
    import atexit

    main_thread = threading.main_thread()
    if any(t is not main_thread and not t.daemon for t in threading.enumerate()):
        sys.exit(code)
    atexit._run_exitfuncs()
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (BrokenPipeError, ValueError):
        pass
    os._exit(code)


def _take_sigint() -> None:
    # a shell starts a background job (`rosl topic hz /x &`) with SIGINT ignored: take it
    # anyway, so that `kill -INT` ends any command as Ctrl-C does
    if (
        threading.current_thread() is threading.main_thread()
        and signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    ):
        signal.signal(signal.SIGINT, signal.default_int_handler)


def _signalled() -> int | None:
    """The SIGINT/SIGTERM that ended rosl's context in this command, if one did."""
    context = sys.modules.get("rosl.node.context")
    return None if context is None else context.default_context.signalled


def _flush_quietly() -> None:
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _silence_stdout()


def _silence_stdout() -> None:
    # stdout's reader went away (`rosl ... | head`): send the rest to /dev/null quietly
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())


def _exit(code: int, leave: bool = False) -> int:
    if _as_script():
        if leave:
            _leave(code)
        sys.exit(code)
    return code


if __name__ == "__main__":
    main()
