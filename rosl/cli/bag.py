"""``rosl bag``: record, info, reindex (play, diff, filter, convert are added alongside)."""

from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any

import click

from rosl.cli import render
from rosl.cli.options import GreedyOption, domain_option


@click.group("bag")
def command() -> None:
    """Various rosbag related sub-commands."""


@command.command("record")
@click.argument("topics", nargs=-1)
@click.option(
    "-a",
    "--all",
    "all_topics",
    is_flag=True,
    help="Record all topics (and with --include-services, all services)",
)
@click.option(
    "-o",
    "--output",
    type=click.Path(path_type=Path),
    default=None,
    help="Output folder (default rosbag2_<date>)",
)
@click.option(
    "-e",
    "--exclude",
    "--exclude-regex",
    "exclude",
    default=None,
    help="Do not record topics matching this regular expression",
)
@click.option(
    "--include-services",
    is_flag=True,
    help="Also record service requests and responses as service events",
)
@click.option("--include-hidden-topics", is_flag=True, help="Also record hidden topics")
@click.option(
    "-b", "--max-bag-size", type=int, default=0, help="Split the bag at this many bytes (0: never)"
)
@click.option(
    "-d",
    "--max-bag-duration",
    type=float,
    default=0.0,
    help="Split the bag after this many seconds (0: never)",
)
@click.option(
    "--compression-format",
    type=click.Choice(["zstd", "lz4"]),
    default=None,
    help="Compress MCAP chunks",
)
@click.option(
    "--distro",
    default=None,
    help="Write metadata.yaml for this ROS distro's rosbag2 (default: $ROS_DISTRO, else humble)",
)
@domain_option
def record(topics: tuple[str, ...], all_topics: bool, output: Path | None, **options: Any) -> None:
    """Record the bus to a rosbag2 folder (MCAP)."""
    import datetime

    from rosl.bag.recorder import Recorder

    if not all_topics and not topics:
        raise click.UsageError("name topics to record, or -a/--all for everything")
    folder = output or Path(datetime.datetime.now().strftime("rosbag2_%Y_%m_%d-%H_%M_%S"))
    recorder = Recorder(
        folder, topics=None if all_topics else list(topics), exclude=options["exclude"],
        services=options["include_services"], include_hidden=options["include_hidden_topics"],
        max_bag_size=options["max_bag_size"], max_bag_duration=options["max_bag_duration"],
        compression=options["compression_format"], domain=options["domain_id"],
        ros_distro=options["distro"],
    )  # fmt: skip
    stop = {"now": False}

    def request_stop(signum: int, frame: Any) -> None:
        stop["now"] = True

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, request_stop)
    recorder.start()
    try:
        recorder.run(lambda: stop["now"])
    finally:
        recorder.close()


@command.command("info")
@click.argument("bag", type=click.Path(path_type=Path))
@click.option("--json", "as_json", is_flag=True, help="Print the information as JSON")
@click.option("-t", "--topic-name", is_flag=True, help="Only display topic names.")
@click.option(
    "-v", "--verbose", is_flag=True, help="Also size contributions and service requests/responses"
)
@click.option("--sort", default="name", help="Sort topics and services by name, type or count")
def info(bag: Path, as_json: bool, topic_name: bool, verbose: bool, sort: str) -> None:
    """Print information about a bag (a folder or an .mcap file)."""
    from rosl.bag import info as bag_info

    if topic_name and verbose:
        render.warn(bag_info.BOTH_FLAGS)
    data = bag_info.summary(bag, verbose=verbose, sort=sort)
    names = topic_name and not verbose
    if as_json:
        shown = [t["name"] for t in data["topics"]] if names else data
        render.text(json.dumps(shown, indent=2) + "\n")
    elif names:
        render.lines([t["name"] for t in data["topics"]])  # nothing at all when there is none
    else:
        render.text(bag_info.text(data))


@command.command("reindex")
@click.argument("bag", type=click.Path(path_type=Path))
@click.option(
    "--keep-corrupt",
    is_flag=True,
    help="Keep the messages of chunks whose CRC check fails (left out by default)",
)
def reindex(bag: Path, keep_corrupt: bool) -> None:
    """Repair a recording cut short or damaged (rebuild index and metadata.yaml, lose nothing)."""
    from rosl.bag.reindex import reindex as run

    render.lines(run(bag, keep_corrupt=keep_corrupt))


@command.command("play")
@click.argument("bag", type=click.Path(path_type=Path))
@click.option("-r", "--rate", type=float, default=1.0, help="Rate at which to play back (> 0)")
@click.option("-l", "--loop", is_flag=True, help="Play the bag again and again")
@click.option(
    "--clock",
    type=float,
    is_flag=False,
    flag_value=40.0,
    default=None,
    help="Publish the bag's time on /clock at this rate in Hz (flag alone: 40)",
)
@click.option("--topics", cls=GreedyOption, multiple=True, help="Play only these topics")
@click.option(
    "--start-offset", type=float, default=0.0, help="Start this many seconds into the bag"
)
@click.option("-m", "--remap", cls=GreedyOption, multiple=True, help="Rename topics: old:=new ...")
@click.option(
    "--read-ahead-queue-size", type=int, default=1000, help="Messages kept read ahead (1000)"
)
@click.option("-p", "--start-paused", is_flag=True, help="Start paused (SPACE resumes)")
@click.option("--disable-keyboard-controls", is_flag=True, help="Ignore SPACE and the arrow keys")
@domain_option
def play(bag: Path, **options: Any) -> None:
    """Play back a bag: the recorded bytes with their original timing."""
    import sys

    from rosl.bag.player import Player, PlayOptions, parse_remap

    player = Player(bag, PlayOptions(
        rate=options["rate"], loop=options["loop"], clock_hz=options["clock"],
        topics=options["topics"], start_offset=options["start_offset"],
        remap=parse_remap(list(options["remap"])), read_ahead=options["read_ahead_queue_size"],
        domain=options["domain_id"],
        keyboard=not options["disable_keyboard_controls"] and sys.stdin.isatty(),
        start_paused=options["start_paused"],
    ), log=render.warn)  # fmt: skip
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda signum, frame: player.stop())
    render.lines([player.play().summary()])


@command.command("diff")
@click.argument("golden", type=click.Path(path_type=Path))
@click.argument("new", type=click.Path(path_type=Path))
@click.option("--topics", cls=GreedyOption, multiple=True, help="Compare only these topics")
@click.option("--exclude", default=None, help="Leave out topics matching this regex")
@click.option(
    "--tolerance", type=float, default=1e-3, help="Largest float difference accepted (1e-3)"
)
@click.option(
    "--time-tolerance",
    type=float,
    default=None,
    help="Largest difference of relative log times in seconds (default: not checked)",
)
@click.option(
    "--ignore-field",
    multiple=True,
    help="Do not compare this field path (e.g. header.stamp); repeatable",
)
@click.option("--max-lines", type=int, default=20, help="Differences to print (20)")
def diff(golden: Path, new: Path, **options: Any) -> int:
    """Compare two bags message by message; exit 0 when they match, 1 when not."""
    from rosl.bag.diff import compare

    result = compare(
        golden, new, topics=list(options["topics"]) or None, exclude=options["exclude"],
        tolerance=options["tolerance"], time_tolerance=options["time_tolerance"],
        ignore_fields=options["ignore_field"], limit=options["max_lines"],
    )  # fmt: skip
    render.text(result.text())
    return 0 if result.matched else 1


@command.command("filter")
@click.argument("source", type=click.Path(path_type=Path))
@click.argument("output", type=click.Path(path_type=Path))
@click.option("--topics", cls=GreedyOption, multiple=True, help="Keep only these topics")
@click.option("--exclude", default=None, help="Drop topics matching this regex")
@click.option("--start", type=float, default=None, help="Seconds after the bag's start")
@click.option("--end", type=float, default=None, help="Seconds after the bag's start")
@click.option(
    "--compression-format",
    type=click.Choice(["zstd", "lz4", "none"]),
    default=None,
    help="Chunk compression of the output (default: the input's)",
)
@click.option(
    "--distro", default=None, help="Write metadata for this ROS distro (default: the input's)"
)
def filter_(source: Path, output: Path, **options: Any) -> None:
    """Write a new bag with the selected topics and time window of another."""
    from rosl.bag.trim import copy

    result = copy(
        source, output, topics=list(options["topics"]) or None, exclude=options["exclude"],
        start=options["start"], end=options["end"], compression=options["compression_format"],
        ros_distro=options["distro"],
    )  # fmt: skip
    for line in result.warnings:
        render.warn(line)
    render.lines([result.summary()])


@command.command("convert")
@click.argument("source", type=click.Path(path_type=Path))
@click.argument("output", type=click.Path(path_type=Path))
@click.option(
    "--compression-format",
    type=click.Choice(["zstd", "lz4", "none"]),
    default=None,
    help="Chunk compression of the output (default: the input's)",
)
@click.option(
    "--distro", default=None, help="Write metadata for this ROS distro (default: the input's)"
)
@click.option(
    "-s",
    "--storage",
    type=click.Choice(["mcap", "sqlite3"]),
    default="mcap",
    show_default=True,
    help="Storage of the output: one .mcap file, or one .db3 file (rosbag2's sqlite3)",
)
def convert(
    source: Path, output: Path, compression_format: str | None, distro: str | None, storage: str
) -> None:
    """Rewrite a bag into one MCAP file (recompressed with --compression-format) or one .db3."""
    from rosl.bag.trim import copy

    if storage == "sqlite3" and compression_format not in (None, "none"):
        raise click.UsageError("--compression-format compresses MCAP chunks, not sqlite3")
    result = copy(
        source, output, compression=compression_format, ros_distro=distro, storage=storage
    )
    for line in result.warnings:
        render.warn(line)
    render.lines([result.summary()])
