"""``rosl node``: list, info."""

from __future__ import annotations

import click

from rosl.cli import render
from rosl.cli.options import domain_option
from rosl.introspection import nodes
from rosl.introspection.session import Session


@click.group("node")
def command() -> None:
    """Various node related sub-commands."""


@command.command("list")
@click.option(
    "-a", "--all", "include_hidden", is_flag=True, help="Display all nodes even hidden ones"
)
@click.option(
    "-c",
    "--count-nodes",
    "--count",
    "count",
    is_flag=True,
    help="Only display the number of nodes discovered",
)
@domain_option
def list_(include_hidden: bool, count: bool, domain_id: int | None) -> None:
    """Output a list of available nodes."""
    with Session(domain_id) as session:
        lines, warnings = nodes.list_nodes(session, include_hidden=include_hidden, count=count)
    for warning in warnings:
        render.warn(warning)
    render.lines(lines)


@command.command("info")
@click.argument("node_name")
@click.option(
    "--include-hidden", is_flag=True, help="Display hidden topics, services, and actions as well"
)
@domain_option
def info(node_name: str, include_hidden: bool, domain_id: int | None) -> None:
    """Output information about a node."""
    with Session(domain_id) as session:
        lines, warnings = nodes.node_info(session, node_name, include_hidden=include_hidden)
    for warning in warnings:
        render.warn(warning)
    render.lines(lines)
