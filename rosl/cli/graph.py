"""``rosl graph``: rqt_graph without a GUI — DOT (default), Mermaid or text; files; --watch."""

from __future__ import annotations

from pathlib import Path

import click

from rosl.cli import render
from rosl.cli.options import domain_option
from rosl.introspection import graph_view
from rosl.introspection.session import Session


@click.command("graph")
@click.option(
    "-o",
    "--output",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Write FILE (.dot/.gv, .mmd, .txt; .svg/.png/.pdf need Graphviz's dot)",
)
@click.option("--mermaid", "fmt", flag_value="mermaid", help="Print a Mermaid flowchart")
@click.option("--text", "fmt", flag_value="text", help="Print an indented text tree")
@click.option("--dot", "fmt", flag_value="dot", default=True, help="Print Graphviz DOT (default)")
@click.option("--nodes-only", is_flag=True, help="Node-to-node edges labelled with topic names")
@click.option("--services", is_flag=True, help="Also draw services (client -> service -> server)")
@click.option("--hide-dead-sinks", is_flag=True, help="Hide topics without subscribers")
@click.option("--hide-leaf-topics", is_flag=True, help="Hide topics with one connection only")
@click.option("--hide-debug", is_flag=True, help="Hide /rosout, /rviz*, /clock... and _names")
@click.option("--hide-params", is_flag=True, help="Hide /parameter_events and parameter services")
@click.option(
    "--include",
    multiple=True,
    metavar="REGEX",
    help="Only names matching REGEX, with their direct neighbours (repeatable)",
)
@click.option(
    "--exclude",
    multiple=True,
    metavar="REGEX",
    help="Drop node/topic names matching REGEX (repeatable)",
)
@click.option("--include-hidden", is_flag=True, help="Show hidden nodes and topics too")
@click.option("--watch", is_flag=True, help="Print again whenever the graph changes (Ctrl-C ends)")
@domain_option
def command(
    output: Path | None,
    fmt: str,
    nodes_only: bool,
    services: bool,
    hide_dead_sinks: bool,
    hide_leaf_topics: bool,
    hide_debug: bool,
    hide_params: bool,
    include: tuple[str, ...],
    exclude: tuple[str, ...],
    include_hidden: bool,
    watch: bool,
    domain_id: int | None,
) -> None:
    """The node/topic graph as rqt_graph draws it, with nothing hidden by default."""
    options = graph_view.GraphOptions(
        services=services,
        nodes_only=nodes_only,
        hide_dead_sinks=hide_dead_sinks,
        hide_leaf_topics=hide_leaf_topics,
        hide_debug=hide_debug,
        hide_params=hide_params,
        include=include,
        exclude=exclude,
        include_hidden=include_hidden,
    )
    if output is not None:
        graph_view.output_format(output)  # fail before touching the bus
    with Session(domain_id) as session:
        if output is not None:
            graph_view.export(session, options, output)
        elif not watch:
            render.text(graph_view.render(graph_view.model(session, options), fmt, nodes_only))
        else:
            for index, picture in enumerate(graph_view.watch(session, options, fmt)):
                if render.use_color():
                    click.clear()
                elif index:
                    render.text("---\n")
                render.text(picture)
