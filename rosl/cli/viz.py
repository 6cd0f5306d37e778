"""``rosl viz [BAG] -o FILE``: the world, paths, last scan and frames as a picture (RViz's job)."""

from __future__ import annotations

from pathlib import Path

import click

from rosl.cli import render
from rosl.cli.options import domain_option


@click.command("viz")
@click.argument("bag", required=False, type=click.Path(path_type=Path))
@click.option(
    "-o",
    "--output",
    type=click.Path(path_type=Path),
    default=None,
    help="Picture to write: .png or .svg (default: BAG.png, or viz.png when live)",
)
@click.option(
    "--fixed-frame",
    "-f",
    default=None,
    help="The frame everything is drawn in (RViz's Fixed Frame)  [default: odom, or the "
    "odometry's frame when there is no odom]",
)
@click.option(
    "-d",
    "--display-config",
    type=click.Path(path_type=Path),
    default=None,
    help="An RViz config (.rviz): its Fixed Frame is used (rviz2 -d FILE)",
)
@click.option(
    "--duration",
    type=float,
    default=2.0,
    show_default=True,
    help="Live: seconds to listen before drawing",
)
@domain_option
def command(
    bag: Path | None,
    output: Path | None,
    fixed_frame: str | None,
    display_config: Path | None,
    duration: float,
    domain_id: int | None,
) -> None:
    """Draw a bag (`rosl viz run1 -o path.png`) or the live system (`rosl viz -o now.png`)."""
    from rosl.introspection import viz

    if fixed_frame is None and display_config is not None:
        fixed_frame = viz.rviz_fixed_frame(display_config)

    if bag is not None:
        if not bag.exists():
            raise click.BadParameter(f"no bag at {bag}", param_hint="BAG")
        target = output or Path(f"{str(bag).rstrip('/')}.png")
        builder = viz.from_bag(bag, fixed_frame)
        title = bag.name
    else:
        from rosl.introspection.session import Session

        target = output or Path("viz.png")
        with Session(domain_id) as session:
            builder = viz.live(session, fixed_frame, duration)
        title = "live"
    written = viz.draw(builder, target, title)
    render.lines([*([builder.note] if builder.note else []), f"wrote {written}"])
