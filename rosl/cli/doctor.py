"""``rosl doctor``: check the setup (domain, multicast, packages, interfaces, graph)."""

from __future__ import annotations

import click

from rosl.cli import render
from rosl.cli.options import domain_option
from rosl.introspection import doctor
from rosl.introspection.session import Session


@click.command("doctor")
@click.option("-r", "--report", is_flag=True, help="Print the platform/network/topic report too")
@domain_option
@click.pass_context
def command(ctx: click.Context, report: bool, domain_id: int | None) -> None:
    """Check the setup and print one line per check; exit 1 when a check fails."""
    with Session(domain_id) as session:
        diagnosis = doctor.diagnose(session, domain_id)
    if report:
        render.lines(doctor.report_lines(diagnosis))
    render.lines(doctor.check_lines(diagnosis))
    if diagnosis.failed:
        ctx.exit(1)
