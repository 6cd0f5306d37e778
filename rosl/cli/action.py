"""``rosl action``: list, info, type, send_goal."""

from __future__ import annotations

import click

from rosl.cli import render
from rosl.cli.options import domain_option
from rosl.introspection import actions
from rosl.introspection.session import Session


@click.group("action")
def command() -> None:
    """Various action related sub-commands."""


@command.command("list")
@click.option("-t", "--show-types", is_flag=True, help="Additionally show the action type")
@click.option(
    "-c", "--count-actions", "count", is_flag=True, help="Only display the number of actions"
)
@domain_option
def list_(show_types: bool, count: bool, domain_id: int | None) -> None:
    """Output a list of action names."""
    with Session(domain_id) as session:
        render.lines(actions.list_actions(session, show_types=show_types, count=count))


@command.command("info")
@click.argument("action_name")
@click.option("-t", "--show-types", is_flag=True, help="Additionally show the action type")
@click.option(
    "-c", "--count", is_flag=True, help="Only display the number of action clients and servers"
)
@domain_option
def info(action_name: str, show_types: bool, count: bool, domain_id: int | None) -> None:
    """Print information about an action."""
    with Session(domain_id) as session:
        render.lines(actions.action_info(session, action_name, show_types=show_types, count=count))


@command.command("type")
@click.argument("action_name")
@domain_option
def type_(action_name: str, domain_id: int | None) -> None:
    """Print an action's type (an unknown action prints nothing and exits 1, as ros2)."""
    with Session(domain_id) as session:
        types = actions.action_types(session, action_name)
    if not types:
        raise click.exceptions.Exit(1)
    render.lines(types)


@command.command("send_goal")
@click.argument("action_name")
@click.argument("action_type")
@click.argument("goal", required=False, default="{}")
@click.option("-f", "--feedback", is_flag=True, help="Echo feedback messages for the goal")
@click.option(
    "--timeout",
    type=float,
    default=actions.DEFAULT_TIMEOUT,
    show_default=True,
    help="Seconds to wait for the action server",
)
@domain_option
def send_goal(
    action_name: str,
    action_type: str,
    goal: str,
    feedback: bool,
    timeout: float,
    domain_id: int | None,
) -> None:
    """Send an action goal (GOAL in YAML, e.g. '{order: 5}')."""
    from rosl.idl.yaml_io import parse_yaml_mapping

    values = parse_yaml_mapping(goal, "goal values")
    with Session(domain_id) as session:
        for block in actions.send_goal(
            session, action_name, action_type, values, feedback=feedback, timeout=timeout
        ):
            render.lines([block])
