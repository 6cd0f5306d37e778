"""``rosl launch_test FILE [name:=value ...]``: ROS 2's ``launch_test`` (launch_testing)."""

from __future__ import annotations

from pathlib import Path

import click

from rosl.cli.options import domain_option, export_domain


@click.command("launch_test", context_settings={"ignore_unknown_options": True})
@click.argument("launch_test_file")
@click.argument("launch_arguments", nargs=-1, type=click.UNPROCESSED)
@click.option(
    "-s",
    "--show-args",
    "--show-arguments",
    "show_args",
    is_flag=True,
    help="Show arguments that may be given to the launch test",
)
@click.option(
    "--package-name",
    default=None,
    help="Name of the package the test is in (names the test module)",
)
@click.option("-v", "--verbose", is_flag=True, help="Run with verbose output")
@click.option(
    "--junit-xml",
    "junit_xml",
    default=None,
    metavar="PATH",
    help="Write a JUnit XML report (as colcon reads) to PATH",
)
@domain_option
def command(
    launch_test_file: str,
    launch_arguments: tuple[str, ...],
    show_args: bool,
    package_name: str | None,
    verbose: bool,
    junit_xml: str | None,
    domain_id: int | None,
) -> int:
    """Run a launch test: its launch, active tests, then post-shutdown tests (exit 0/1)."""
    from rosl.launch.loader import parse_arguments
    from rosl.launch.testing import launch_test

    export_domain(domain_id)
    arguments = parse_arguments(list(launch_arguments))
    code = launch_test.main(
        Path(launch_test_file), arguments, show_args=show_args, package_name=package_name,
        verbose=verbose, junit_xml=Path(junit_xml) if junit_xml else None,
    )  # fmt: skip
    if code == 130:  # a Ctrl-C: CPython must not end the process by SIGINT after all (-2)
        from rosl.pkg import interrupts

        interrupts.caught()
    return code
