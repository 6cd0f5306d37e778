"""``rosl viz [BAG] -o FILE``: the world, paths, last scan and frames as a picture (RViz's job).

``rosl viz --serve`` draws the same live, in a web page rosl serves (with the node graph).
"""

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
@click.option("--serve", is_flag=True, help="Live, in a web page: the world and the node graph")
@click.option(
    "--port",
    type=click.IntRange(0, 65535),
    default=8080,
    show_default=True,
    help="--serve: the page's port (0: any free one)",
)
@click.option(
    "--address",
    default="127.0.0.1",
    show_default=True,
    help="--serve: the address to listen on (0.0.0.0: every interface)",
)
@domain_option
def command(
    bag: Path | None,
    output: Path | None,
    fixed_frame: str | None,
    display_config: Path | None,
    duration: float,
    serve: bool,
    port: int,
    address: str,
    domain_id: int | None,
) -> None:
    """Draw a bag (`rosl viz run1 -o path.png`) or the live system (`rosl viz -o now.png`).

    `rosl viz --serve` shows the live system in a browser page instead, updated as it runs.
    """
    from rosl.introspection import viz

    if fixed_frame is None and display_config is not None:
        fixed_frame = viz.rviz_fixed_frame(display_config)
    if serve:
        _serve(bag, output, fixed_frame, address, port, domain_id)
        return

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


def _serve(
    bag: Path | None,
    output: Path | None,
    fixed_frame: str | None,
    address: str,
    port: int,
    domain_id: int | None,
) -> None:
    """``--serve``: the live view in a browser page, until Ctrl-C."""
    if bag is not None:
        raise click.UsageError(f"--serve shows the live bus: give no BAG ({bag}), or drop --serve")
    if output is not None:
        raise click.UsageError("--serve draws in the browser: -o/--output is for a picture")
    from rosl.introspection import live_view
    from rosl.introspection.session import Session

    with Session(domain_id) as session:
        live_view.serve(
            session, fixed_frame, address, port,
            lambda url: render.lines([f"live view at {url} (Ctrl-C to stop)"]),
        )  # fmt: skip
