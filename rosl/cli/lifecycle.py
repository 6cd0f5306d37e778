"""``rosl lifecycle``: nodes, list, get, set (ros2lifecycle's verbs and texts)."""

from __future__ import annotations

import click

from rosl.cli import render
from rosl.cli.options import domain_option
from rosl.introspection import lifecycle
from rosl.introspection.session import Session

_TIMEOUT_HELP = "Maximum time to wait for each answer in seconds (default: 5)"


@click.group("lifecycle")
def command() -> None:
    """Various lifecycle related sub-commands."""


@command.command("nodes")
@click.option(
    "-a", "--all", "include_hidden", is_flag=True, help="Display all nodes even hidden ones"
)
@click.option(
    "-c", "--count-nodes", "count", is_flag=True, help="Only display the number of nodes discovered"
)
@domain_option
def nodes(include_hidden: bool, count: bool, domain_id: int | None) -> None:
    """Output a list of nodes with lifecycle."""
    with Session(domain_id) as session:
        lines = lifecycle.list_nodes(session, include_hidden=include_hidden, count=count)
    render.lines(lines)


@command.command("list")
@click.argument("node_name")
@click.option("--include-hidden-nodes", is_flag=True, help="Consider hidden nodes as well")
@click.option("-a", "--all", "show_all", is_flag=True, help="Display all existing transitions")
@click.option("--timeout", type=float, default=lifecycle.DEFAULT_TIMEOUT, help=_TIMEOUT_HELP)
@domain_option
def list_(
    node_name: str,
    include_hidden_nodes: bool,
    show_all: bool,
    timeout: float,
    domain_id: int | None,
) -> None:
    """Output a list of available transitions."""
    hidden = include_hidden_nodes
    with Session(domain_id) as session:
        lines = lifecycle.list_transitions(
            session, node_name, show_all=show_all, include_hidden=hidden, timeout=timeout
        )
    render.lines(lines)


@command.command("get")
@click.argument("node_name", required=False)
@click.option(
    "--include-hidden-nodes", "-a", "--all", "include_hidden", is_flag=True,
    help="Consider hidden nodes as well",
)  # fmt: skip
@click.option("--timeout", type=float, default=lifecycle.DEFAULT_TIMEOUT, help=_TIMEOUT_HELP)
@domain_option
def get(node_name: str | None, include_hidden: bool, timeout: float, domain_id: int | None) -> None:
    """Get lifecycle state for one or more nodes."""
    with Session(domain_id) as session:
        lines, problems = lifecycle.get_states(
            session, node_name, include_hidden=include_hidden, timeout=timeout
        )
    render.lines(lines)
    for problem in problems:
        render.warn(problem)


@command.command("set")
@click.argument("node_name")
@click.argument("transition")
@click.option("--include-hidden-nodes", is_flag=True, help="Consider hidden nodes as well")
@click.option("--timeout", type=float, default=lifecycle.DEFAULT_TIMEOUT, help=_TIMEOUT_HELP)
@domain_option
def set_(
    node_name: str,
    transition: str,
    include_hidden_nodes: bool,
    timeout: float,
    domain_id: int | None,
) -> None:
    """Trigger lifecycle state transition."""
    hidden = include_hidden_nodes
    with Session(domain_id) as session:
        said = lifecycle.set_state(
            session, node_name, transition, include_hidden=hidden, timeout=timeout
        )
    render.lines([said])
