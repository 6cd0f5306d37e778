"""``rosl service``: list, type, find, info, call."""

from __future__ import annotations

import click

from rosl.cli import render
from rosl.cli.options import domain_option
from rosl.cli.options import include_hidden as hidden_flag
from rosl.introspection import services
from rosl.introspection.session import Session, visible

hidden_option = click.option(
    "--include-hidden-services",
    "include_hidden",
    is_flag=True,
    help="Consider hidden services as well",
)


@click.group("service")
@hidden_option
def command(include_hidden: bool) -> None:
    """Various service related sub-commands."""
    del include_hidden  # read by the verbs: `rosl service --include-hidden-services list`


@command.command("list")
@click.option("-t", "--show-types", is_flag=True, help="Additionally show the service type")
@click.option(
    "-c", "--count-services", "count", is_flag=True, help="Only display the number of services"
)
@hidden_option
@domain_option
def list_(show_types: bool, count: bool, include_hidden: bool, domain_id: int | None) -> None:
    """Output a list of available services."""
    with Session(domain_id) as session:
        render.lines(
            services.list_services(
                session,
                show_types=show_types,
                count=count,
                include_hidden=hidden_flag(include_hidden),
            )
        )


@command.command("type")
@click.argument("service_name")
@hidden_option
@domain_option
def type_(service_name: str, include_hidden: bool, domain_id: int | None) -> None:
    """Output a service's type (an unknown or hidden one prints nothing and exits 1, as ros2)."""
    with Session(domain_id) as session:
        types = session.graph().services().get(service_name)
    if not types or not visible(service_name, hidden_flag(include_hidden)):
        raise click.exceptions.Exit(1)
    render.lines(types)


@command.command("find")
@click.argument("service_type")
@click.option(
    "-c", "--count-services", "count", is_flag=True, help="Only display the number of services"
)
@hidden_option
@domain_option
def find(service_type: str, count: bool, include_hidden: bool, domain_id: int | None) -> None:
    """Output a list of available services of a given type."""
    with Session(domain_id) as session:
        found = services.find_services(
            session, service_type, include_hidden=hidden_flag(include_hidden)
        )
        render.lines([str(len(found))] if count else found)


@command.command("info")
@click.argument("service_name")
@domain_option
def info(service_name: str, domain_id: int | None) -> None:
    """Print information about a service."""
    with Session(domain_id) as session:
        render.lines(services.service_info(session, service_name))


@command.command("call")
@click.argument("service_name")
@click.argument("service_type", required=False)
@click.argument("values", required=False, default="{}")
@click.option(
    "-r", "--rate", type=float, default=None, help="Repeat the call at a specific rate in Hz"
)
@click.option(
    "--timeout",
    type=float,
    default=services.DEFAULT_TIMEOUT,
    show_default=True,
    help="Seconds to wait for the service, and for each response",
)
@domain_option
def call(
    service_name: str,
    service_type: str | None,
    values: str,
    rate: float | None,
    timeout: float,
    domain_id: int | None,
) -> None:
    """Call a service (TYPE may be left out: the graph knows it)."""
    from rosl.idl.yaml_io import parse_yaml_mapping

    if service_type is not None and service_type.lstrip().startswith("{"):
        values = service_type  # `call /srv "{a: 1}"` without a type
        service_type = None
    data = parse_yaml_mapping(values, "request values")
    with Session(domain_id) as session:
        for block in services.call(
            session, service_name, service_type, data, rate=rate, timeout=timeout
        ):
            render.text(block + "\n")


@command.command("echo")
@click.argument("service_name")
@click.argument("service_type", required=False)
@click.option("-l", "--truncate-length", type=int, default=128, help="Truncate strings and arrays")
@click.option("-f", "--full-length", is_flag=True, help="Do not truncate")
@click.option("--once", is_flag=True, help="Print the first event and exit")
@domain_option
def echo(
    service_name: str,
    service_type: str | None,
    truncate_length: int,
    full_length: bool,
    once: bool,
    domain_id: int | None,
) -> None:
    """Echo a service's requests and responses as service events (no setup needed)."""
    with Session(domain_id) as session:
        for block in services.echo(
            session,
            service_name,
            service_type,
            truncate_length=None if full_length else truncate_length,
            once=once,
        ):
            render.text(block + "\n")
