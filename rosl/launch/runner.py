"""``rosl launch``: load a launch file, show its arguments or plan, or run it to the end."""

from __future__ import annotations

import os
import shlex
from typing import TYPE_CHECKING

from rosl.launch.context import LaunchContext
from rosl.launch.description import process
from rosl.launch.loader import load_description
from rosl.launch.substitutions import describe
from rosl.launch.supervisor import Supervisor

if TYPE_CHECKING:
    from pathlib import Path


def show_arguments(path: Path) -> list[str]:
    """The lines ``ros2 launch --show-args`` prints."""
    description = load_description(path)
    arguments = description.get_launch_arguments()
    lines = ["Arguments (pass arguments as '<name>:=<value>'):"]
    conditional = False
    for argument in arguments:
        star = "*" if argument.conditionally_included else ""
        conditional = conditional or argument.conditionally_included
        text = f"\n    '{argument.name}'{star}:\n        {argument.description}"
        if argument.default_value is not None:
            text += f"\n        (default: {describe(argument.default_value)})"
        lines.append(text)
    if not arguments:
        lines.append("\n  No arguments.")
    elif conditional:
        lines.append("\n* argument(s) which are only declared if specific conditions occur")
    return lines


def plan(path: Path, arguments: dict[str, str]) -> list[str]:
    """What would start (``--print``/``--dry-run``): one block per process."""
    supervisor = Supervisor(dry_run=True)
    context = LaunchContext(supervisor, arguments)
    context.files.append(path)
    process(load_description(path).entities, context)
    lines = []
    for index, spec in enumerate(supervisor.planned, start=1):
        lines.append(f"[{spec.name}-{index}] {shlex.join(spec.cmd)}")
        details = spec.details
        if details:
            lines.append(
                f"    node: {details.get('name') or details.get('executable')} "
                f"(package {details.get('package')}, namespace {details.get('namespace')})"
            )
            for key, value in sorted(details.get("parameters", {}).items()):
                lines.append(f"    param: {key} = {value!r}")
            for source, target in details.get("remappings", []):
                lines.append(f"    remap: {source} -> {target}")
        lines.append(f"    output: {spec.output}" + ("; respawn" if spec.respawn else ""))
    if not lines:
        lines.append("(nothing would start)")
    return lines


def launch(path: Path, arguments: dict[str, str], *, supervisor: Supervisor | None = None) -> int:
    """Run a launch file until every process has ended (or Ctrl-C); return the exit status."""
    chosen = supervisor or Supervisor()
    chosen.log("INFO", "launch", f"All log files can be found below {chosen.log_dir}")
    chosen.log("INFO", "launch", "Default logging verbosity is set to INFO")
    context = LaunchContext(chosen, arguments)
    context.files.append(path)
    os.environ.setdefault("PYTHONUNBUFFERED", "1")
    try:
        process(load_description(path).entities, context)
    except BaseException:
        chosen.shutdown("launch file failed")
        chosen.run()
        raise
    return chosen.run()
