"""``rosl interface``: list, packages, package, show, proto."""

from __future__ import annotations

import sys

import click

from rosl.cli import render
from rosl.idl import describe, registry
from rosl.idl.errors import InterfaceError


@click.group("interface")
def command() -> None:
    """Show information about ROS interfaces."""


def _kinds(msgs: bool, srvs: bool, actions: bool) -> tuple[str, ...]:
    chosen = tuple(k for k, on in (("msg", msgs), ("srv", srvs), ("action", actions)) if on)
    return chosen or ("msg", "srv", "action")


@command.command("list")
@click.option("-m", "--only-msgs", is_flag=True, help="Print out only the message types")
@click.option("-s", "--only-srvs", is_flag=True, help="Print out only the service types")
@click.option("-a", "--only-actions", is_flag=True, help="Print out only the action types")
def list_(only_msgs: bool, only_srvs: bool, only_actions: bool) -> None:
    """List all interface types available."""
    titles = {"msg": "Messages:", "srv": "Services:", "action": "Actions:"}
    index = registry.all_types()
    for kind in _kinds(only_msgs, only_srvs, only_actions):
        render.lines([titles[kind], *(f"    {name}" for name in index[kind])])


@command.command("packages")
@click.option("-m", "--only-msgs", is_flag=True, help="Only list packages that generate messages")
@click.option("-s", "--only-srvs", is_flag=True, help="Only list packages that generate services")
@click.option("-a", "--only-actions", is_flag=True, help="Only list packages that generate actions")
def packages(only_msgs: bool, only_srvs: bool, only_actions: bool) -> None:
    """Output a list of packages that provide interfaces."""
    render.lines(registry.interface_packages(_kinds(only_msgs, only_srvs, only_actions)))


@command.command("package")
@click.option("-m", "--only-msgs", is_flag=True, help="Print out only the message types")
@click.option("-s", "--only-srvs", is_flag=True, help="Print out only the service types")
@click.option("-a", "--only-actions", is_flag=True, help="Print out only the action types")
@click.argument("package_name")
def package(package_name: str, only_msgs: bool, only_srvs: bool, only_actions: bool) -> None:
    """Output a list of available interface types within one package."""
    kinds = _kinds(only_msgs, only_srvs, only_actions)
    render.lines(registry.package_types(package_name, kinds))


def _type_argument(value: str) -> str:
    if value != "-":
        return value
    if sys.stdin is None or sys.stdin.isatty():
        raise InterfaceError(
            "'-' reads the type from a pipe, e.g. `rosl topic type /x | rosl interface show -`"
        )
    line = sys.stdin.readline().strip()
    if not line:
        raise InterfaceError("no type name on standard input")
    return line


@command.command("show")
@click.option(
    "--all-comments",
    is_flag=True,
    help="Show all comments, including for nested interface definitions",
)
@click.option("--no-comments", is_flag=True, help="Show no comments or whitespace")
@click.argument("type_name", metavar="TYPE")
def show(type_name: str, all_comments: bool, no_comments: bool) -> None:
    """Output the interface definition (pkg/msg/Name, pkg/srv/Name, pkg/Name or '-')."""
    if all_comments and no_comments:
        raise click.UsageError("--all-comments and --no-comments cannot be used together")
    render.text(
        describe.show(_type_argument(type_name), all_comments=all_comments, no_comments=no_comments)
    )


@command.command("proto")
@click.option("--no-quotes", is_flag=True, help="if true output has no outer quotes.")
@click.argument("type_name", metavar="TYPE")
def proto(type_name: str, no_quotes: bool) -> None:
    """Output an interface prototype (YAML usable in `topic pub` and `service call`)."""
    yaml_text = describe.prototype(type_name)
    click.echo(yaml_text if no_quotes else f'"{yaml_text}"')
