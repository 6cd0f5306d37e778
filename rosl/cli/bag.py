"""``rosl bag``: record, info, reindex (play, diff, filter, convert are added alongside)."""

from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Any

import click

from rosl.cli import render
from rosl.cli.options import domain_option


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
def info(bag: Path, as_json: bool) -> None:
    """Print information about a bag (a folder or an .mcap file)."""
    from rosl.bag import info as bag_info

    if as_json:
        render.text(json.dumps(bag_info.summary(bag), indent=2) + "\n")
    else:
        render.text(bag_info.text(bag))


@command.command("reindex")
@click.argument("bag", type=click.Path(path_type=Path))
def reindex(bag: Path) -> None:
    """Repair a recording whose recorder stopped abruptly (rebuild index and metadata.yaml)."""
    from rosl.bag.reindex import reindex as run

    render.lines(run(bag))
