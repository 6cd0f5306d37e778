"""``rosl tf``: frames (view_frames, as text, DOT or a file) and echo (tf2_echo)."""

from __future__ import annotations

from pathlib import Path

import click

from rosl.cli import render
from rosl.cli.options import domain_option
from rosl.introspection import tf
from rosl.introspection.session import Session

wait_option = click.option(
    "-t",
    "--wait-time",
    type=float,
    default=2.0,
    show_default=True,
    help="Seconds to listen to /tf and /tf_static",
)


@click.group("tf")
def command() -> None:
    """TF frames: the tree (view_frames) and transforms (tf2_echo)."""


@command.command("frames")
@wait_option
@click.option("--dot", "as_dot", is_flag=True, help="Print view_frames' DOT instead of the tree")
@click.option(
    "-o",
    "--output",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Write FILE: .dot/.gv, .txt, or a picture .svg/.png/.pdf",
)
@domain_option
def frames(wait_time: float, as_dot: bool, output: Path | None, domain_id: int | None) -> None:
    """Show the TF frame tree (view_frames): who broadcasts each edge, how fast."""
    if output is not None:
        tf.output_format(output)  # fail before listening
    with Session(domain_id) as session:
        buffer = tf.frames(session, wait_time)
    if output is not None:
        tf.export(buffer, output)
    else:
        render.text(tf.frames_dot(buffer) if as_dot else tf.frames_text(buffer))


@command.command("echo")
@click.argument("source_frame")
@click.argument("target_frame")
@wait_option
@click.option("--once", is_flag=True, help="Print one transform and exit")
@click.option("-r", "--rate", type=float, default=1.0, show_default=True, help="Prints per second")
@domain_option
def echo(
    source_frame: str,
    target_frame: str,
    wait_time: float,
    once: bool,
    rate: float,
    domain_id: int | None,
) -> None:
    """Print the pose of TARGET_FRAME in SOURCE_FRAME, as tf2_echo does."""
    with Session(domain_id) as session:
        for block in tf.echo(
            session, source_frame, target_frame, wait_time=wait_time, once=once, rate=rate
        ):
            render.text(block + "\n")
