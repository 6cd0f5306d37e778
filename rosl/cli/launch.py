"""``rosl launch PKG FILE [name:=value ...]`` or ``rosl launch PATH [name:=value ...]``.

FILE is a Python (``*.launch.py``), XML (``*.launch.xml``) or YAML (``*.launch.yaml``) launch
file; ``--show-args`` and ``--print`` read all three the same way.
"""

from __future__ import annotations

from pathlib import Path

import click

from rosl.cli import render
from rosl.cli.companion import companion_options
from rosl.cli.options import domain_option, export_domain
from rosl.launch import loader, runner


@click.command("launch", context_settings={"ignore_unknown_options": True})
@click.argument("target")
@click.argument("rest", nargs=-1, type=click.UNPROCESSED)
@click.option(
    "-s",
    "--show-args",
    "--show-arguments",
    "show_args",
    is_flag=True,
    help="Show arguments that may be given to the launch file",
)
@click.option(
    "-p",
    "--print",
    "--print-description",
    "--dry-run",
    "print_plan",
    is_flag=True,
    help="Print what would start (command lines, remaps, parameters) and exit",
)
@click.option(
    "--record",
    "record",
    is_flag=False,
    flag_value="",
    default=None,
    metavar="[DIR]",
    help="Record everything on the bus while the launch runs (rosbag2 folder)",
)
@companion_options
@domain_option
def command(
    target: str,
    rest: tuple[str, ...],
    show_args: bool,
    print_plan: bool,
    record: str | None,
    bridge: bool,
    bridge_port: int,
    serve: bool,
    serve_port: int,
    domain_id: int | None,
) -> int:
    """Run a launch file (Python, XML or YAML): `rosl launch tutorial_pkg my_launch.py`."""
    export_domain(domain_id)
    if (bridge or serve) and not (show_args or print_plan):
        from rosl.cli.companion import companions

        with companions(
            serve=serve_port if serve else None,
            bridge=bridge_port if bridge else None,
            domain=domain_id,
        ):
            return _launch(target, rest, show_args, print_plan, record)
    return _launch(target, rest, show_args, print_plan, record)


def _launch(
    target: str, rest: tuple[str, ...], show_args: bool, print_plan: bool, record: str | None
) -> int:
    args = list(rest)
    if Path(target).is_file() or (
        target.endswith((".py", ".yaml", ".yml", ".xml")) and "/" in target
    ):
        path = Path(target)
    else:
        if not args or ":=" in args[0]:
            raise click.UsageError("give a launch file: rosl launch PKG FILE or rosl launch PATH")
        path = loader.find_in_package(target, args.pop(0))
    arguments = loader.parse_arguments(args)
    if show_args:
        render.lines(runner.show_arguments(path))
        return 0
    if print_plan:
        render.lines(runner.plan(path, arguments))
        return 0
    folder = None
    if record is not None:
        import datetime

        folder = Path(record or datetime.datetime.now().strftime("launch_%Y_%m_%d-%H_%M_%S"))
    code = runner.launch(path, arguments, record=folder)
    if code == 130:  # a Ctrl-C ended the loading: it may have left the launch file's code
        from rosl.pkg import interrupts

        interrupts.caught()  # (else CPython would end the process by SIGINT: status -2)
    return code
