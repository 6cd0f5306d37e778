"""``rosl launch``: load a launch file, show its arguments or plan, or run it to the end."""

from __future__ import annotations

import os
import shlex
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosl.launch.context import LaunchContext
from rosl.launch.description import Action, check_required_arguments, process
from rosl.launch.loader import load_description
from rosl.launch.substitutions import describe
from rosl.launch.supervisor import Supervisor

if TYPE_CHECKING:
    from rosl.launch.description import LaunchDescription


def show_arguments(path: Path) -> list[str]:
    """The lines ``ros2 launch --show-args`` prints."""
    return argument_lines(load_description(path))


def argument_lines(description: LaunchDescription) -> list[str]:
    """The lines ``--show-args`` prints for a loaded description (also ``launch_test -s``)."""
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
    description = load_description(path)
    check_required_arguments(description, context, path)
    process(description.entities, context)
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


def launch(
    path: Path,
    arguments: dict[str, str],
    *,
    supervisor: Supervisor | None = None,
    record: Path | None = None,
) -> int:
    """Run a launch file until every process has ended (or Ctrl-C); return the exit status.

    Args:
        path: the launch file.
        arguments: ``name:=value`` launch arguments.
        supervisor: the supervisor to use (a fresh one by default).
        record: record everything on the bus, from before the first node starts until the
            last one exits, into this folder.
    """
    chosen = supervisor or Supervisor()
    chosen.install_signal_handlers()  # a Ctrl-C from here on stops whatever has started
    try:
        chosen.log("INFO", "launch", f"All log files can be found below {chosen.log_dir}")
        chosen.log("INFO", "launch", "Default logging verbosity is set to INFO")
        if record is not None:
            start_recorder(chosen, record)
        context = LaunchContext(chosen, arguments)
        context.files.append(path)
        os.environ.setdefault("PYTHONUNBUFFERED", "1")
        chosen.loading = not chosen.stopping  # a Ctrl-C from here on ends the loading at once
        try:
            if _starts_nodes(path):  # the zygote warms up while the launch file loads
                chosen.prepare_zygote()
            description = load_description(path)
            check_required_arguments(description, context, path)
            process(description.entities, context)
            chosen.loading = False
        except KeyboardInterrupt:
            if not chosen.interrupted_while_loading:
                raise
        except BaseException:
            chosen.loading = False
            chosen.shutdown("launch file failed")
            chosen.run()
            raise
        code = chosen.run()  # handles a Ctrl-C received while loading first
        return 130 if chosen.interrupted_while_loading else code
    finally:
        chosen.restore_signal_handlers()


def _starts_nodes(path: Path) -> bool:
    """Whether a launch file looks as if it starts ROS nodes (Node, <node>, node:)."""
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return False
    return "node" in text.lower()


def start_recorder(supervisor: Supervisor, folder: Path) -> None:
    """Start ``rosl bag record -a --include-services`` and wait (bounded) until it listens.

    Raises:
        LaunchError: the recorder could not start (e.g. the folder exists).
    """
    import sys

    from rosl.launch.errors import LaunchError
    from rosl.launch.records import ProcessSpec

    cmd = [sys.executable, "-P", "-m", "rosl", "bag", "record", "-a", "--include-services",
           "-o", str(folder)]  # fmt: skip
    spec = ProcessSpec(name="rosbag2_recorder", cmd=cmd, env=dict(os.environ), output="screen",
                       background=True, sigterm_timeout=10.0, sigkill_timeout=5.0)  # fmt: skip
    label = supervisor.start(spec, None, None)
    if not supervisor.wait_for_line(label, "Recording to", timeout=10.0) and not (
        supervisor.stopping  # Ctrl-C meanwhile: nothing more starts, the recorder is stopped
    ):
        supervisor.shutdown("the recorder did not start")
        supervisor.run()
        raise LaunchError("the recorder did not start (its output is above); nothing was launched")


class Record(Action):
    """Record everything on the bus from this point of the launch on (a launch action).

    ``rosl bag record -a --include-services -o OUTPUT`` starts, and the launch goes on once it
    listens; it is stopped last, after every other process, so the bag holds the whole run::

        record = Record()  # a fresh folder; or Record(output="run1")
        return LaunchDescription([record, Node(...), ReadyToTest()]), {"bag": record.output}

    Args:
        output: the bag folder to create (it must not exist); by default ``bag`` in a new
            temporary folder.
    """

    def __init__(self, output: str | Path | None = None, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        if output is None:
            import tempfile

            output = Path(tempfile.mkdtemp(prefix="rosl_record_")) / "bag"
        self.output = Path(output)

    def execute(self, context: LaunchContext) -> None:
        """Start the recorder and wait (bounded) until it records."""
        if context.supervisor is not None and not context.supervisor.dry_run:
            start_recorder(context.supervisor, self.output)
