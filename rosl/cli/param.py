"""``rosl param``: list, get, set, dump, load, describe, delete."""

from __future__ import annotations

from pathlib import Path

import click

from rosl.cli import render
from rosl.cli.options import GreedyOption, domain_option
from rosl.introspection import params
from rosl.introspection.errors import IntrospectionError
from rosl.introspection.session import Session


def _report(outcomes: list[params.Outcome]) -> int:
    """Print ros2's result lines (failures on stderr); 1 if any failed."""
    for ok, line in outcomes:
        if ok:
            render.lines([line])
        else:
            render.warn(line)
    return 0 if all(ok for ok, _ in outcomes) else 1


@click.group("param")
def command() -> None:
    """Various param related sub-commands."""


hidden_nodes_option = click.option(
    "--include-hidden-nodes", "include_hidden", is_flag=True, help="Consider hidden nodes as well"
)


@command.command("list")
@click.argument("node_name", required=False)
@click.option(
    "--filter",
    "filter_regex",
    default=None,
    help="Only parameters matching the regex expression will be showed (re.match)",
)
@click.option(
    "--param-prefixes",
    cls=GreedyOption,
    multiple=True,
    metavar="PREFIX...",
    help="Only list parameters with the provided prefixes",
)
@click.option("--param-type", is_flag=True, help="Print parameter types with parameter names")
@hidden_nodes_option
@domain_option
def list_(
    node_name: str | None,
    filter_regex: str | None,
    param_prefixes: tuple[str, ...],
    param_type: bool,
    include_hidden: bool,
    domain_id: int | None,
) -> None:
    """Output a list of available parameters."""
    with Session(domain_id) as session:
        if node_name:
            params.require_node(session, node_name, include_hidden=include_hidden)
        render.lines(
            params.param_list(
                session,
                node_name,
                filter_regex=filter_regex,
                prefixes=list(param_prefixes),
                param_type=param_type,
                include_hidden=include_hidden,
            )
        )


@command.command("get")
@click.argument("node_name")
@click.argument("parameter_name")
@click.option("--hide-type", is_flag=True, help="Hide the type information")
@hidden_nodes_option
@domain_option
def get(
    node_name: str,
    parameter_name: str,
    hide_type: bool,
    include_hidden: bool,
    domain_id: int | None,
) -> None:
    """Get parameter."""
    with Session(domain_id) as session:
        params.require_node(session, node_name, include_hidden=include_hidden)
        render.text(params.get(session, node_name, parameter_name, hide_type=hide_type) + "\n")


@command.command("set", context_settings={"ignore_unknown_options": True})
@click.argument("node_name")
@click.argument("pairs", nargs=-1, required=True, metavar="NAME VALUE [NAME VALUE ...]")
@click.option("--atomic", is_flag=True, help="Set all parameters or none")
@hidden_nodes_option
@domain_option
def set_(
    node_name: str,
    pairs: tuple[str, ...],
    atomic: bool,
    include_hidden: bool,
    domain_id: int | None,
) -> int:
    """Set parameter(s); values are YAML (1 int, 1.0 double, -1.0, true bool, '[1, 2]')."""
    # unknown options are kept as arguments so that negative values (-1.0) stay values
    for name in pairs[::2]:
        if name.startswith("-"):
            raise click.NoSuchOption(name)
    if len(pairs) % 2:
        raise IntrospectionError(
            "Parameters must be provided as name/value pairs: name value [name value ...]. "
            f"Got {len(pairs)} argument(s)."
        )
    with Session(domain_id) as session:
        params.require_node(session, node_name, include_hidden=include_hidden)
        outcomes = params.set_values(
            session, node_name, list(zip(pairs[::2], pairs[1::2], strict=True)), atomic=atomic
        )
    return _report(outcomes)


@command.command("delete")
@click.argument("node_name")
@click.argument("parameter_name")
@hidden_nodes_option
@domain_option
def delete(
    node_name: str, parameter_name: str, include_hidden: bool, domain_id: int | None
) -> None:
    """Delete parameter."""
    with Session(domain_id) as session:
        params.require_node(session, node_name, include_hidden=include_hidden)
        render.text(params.delete(session, node_name, parameter_name) + "\n")


@command.command("describe")
@click.argument("node_name")
@click.argument("parameter_names", nargs=-1, required=True)
@hidden_nodes_option
@domain_option
def describe(
    node_name: str, parameter_names: tuple[str, ...], include_hidden: bool, domain_id: int | None
) -> None:
    """Show descriptive information about declared parameters."""
    with Session(domain_id) as session:
        params.require_node(session, node_name, include_hidden=include_hidden)
        render.lines(params.describe(session, node_name, list(parameter_names)))


@command.command("dump")
@click.argument("node_name")
@hidden_nodes_option
@click.option(
    "--output-dir",
    default=None,
    help="DEPRECATED: The absolute path where to save the generated file",
)
@click.option("--print", "print_", is_flag=True, help="DEPRECATED: Does nothing.")
@domain_option
def dump(
    node_name: str,
    include_hidden: bool,
    output_dir: str | None,
    print_: bool,
    domain_id: int | None,
) -> None:
    """Show all of the parameters of a node in a YAML file format."""
    with Session(domain_id) as session:
        params.require_node(session, node_name, include_hidden=include_hidden)
        if print_:
            render.warn(
                "WARNING: '--print' is deprecated; this utility prints to stdout by default"
            )
        if output_dir is None or output_dir == ".":  # ros2's print(): a blank line follows
            render.text(params.dump(session, node_name) + "\n")
            return
        path = params.dump_to_dir(session, node_name, output_dir)
    render.warn("WARNING: '--output-dir' is deprecated; use redirection to save to a file")
    render.text(f"Saving to:  {path}\n")


@command.command("load")
@click.argument("node_name")
@click.argument("parameter_file", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "--no-use-wildcard",
    is_flag=True,
    help="Do not load parameters in the '/**' namespace into the node",
)
@hidden_nodes_option
@domain_option
def load(
    node_name: str,
    parameter_file: Path,
    no_use_wildcard: bool,
    include_hidden: bool,
    domain_id: int | None,
) -> int:
    """Load parameter file for a node."""
    with Session(domain_id) as session:
        params.require_node(session, node_name, include_hidden=include_hidden)
        outcomes = params.load(session, node_name, parameter_file, use_wildcard=not no_use_wildcard)
    return _report(outcomes)
