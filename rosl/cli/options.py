"""Option helpers shared by commands."""

from __future__ import annotations

from typing import Any

import click


class GreedyOption(click.Option):
    """An option taking every following value up to the next option, like argparse's ``nargs='+'``.

    ``--dependencies rclpy std_msgs geometry_msgs`` gives all three, as ``ros2`` accepts.
    """

    def add_to_parser(self, parser: Any, ctx: click.Context) -> None:
        """Register the option, then make its parser consume the values that follow it."""
        super().add_to_parser(parser, ctx)
        patched: list[Any] = []
        for name in self.opts:
            option = parser._long_opt.get(name) or parser._short_opt.get(name)
            if option is None or any(option is done for done in patched):
                continue  # one parser option serves all the names (-m and --remap)
            patched.append(option)
            original = option.process

            def process(value: Any, state: Any, _original: Any = original) -> None:
                values = [value]
                while state.rargs and not state.rargs[0].startswith("-"):
                    values.append(state.rargs.pop(0))
                _original(tuple(values), state)

            option.process = process

    def type_cast_value(self, ctx: click.Context, value: Any) -> Any:
        """Flatten the tuples gathered for each occurrence."""
        flat: list[str] = []
        for item in value or ():
            flat.extend(item if isinstance(item, tuple) else (item,))
        return tuple(flat)


def domain_option(command: Any) -> Any:
    """Add ``--domain-id`` (overrides ROSL_DOMAIN_ID / ROS_DOMAIN_ID) and ``--transport``."""
    command = click.option(
        "--transport",
        type=click.Choice(["multicast", "zenoh", "inprocess"]),
        default=None,
        expose_value=False,
        callback=_export_transport,
        help="Transport to use instead of ROSL_TRANSPORT (zenoh: ROS 2's rmw_zenoh).",
    )(command)
    return click.option(
        "--domain-id",
        "domain_id",
        type=int,
        default=None,
        help="Domain to use instead of ROSL_DOMAIN_ID / ROS_DOMAIN_ID.",
    )(command)


def _export_transport(ctx: click.Context, param: click.Parameter, value: str | None) -> None:
    """Make ``--transport`` the transport of this process and of every process it starts."""
    del ctx, param
    if value is not None:
        import os

        os.environ["ROSL_TRANSPORT"] = value


def export_domain(domain_id: int | None) -> None:
    """Make ``--domain-id`` the domain of this process and of every process it starts."""
    if domain_id is None:
        return
    import os

    from rosl.bus.multicast import domain_from_env

    os.environ["ROSL_DOMAIN_ID"] = str(domain_from_env(domain_id))


def include_hidden(flag: bool) -> bool:
    """A verb's ``--include-hidden-*`` flag, or its group's (ros2 takes it on either)."""
    parent = click.get_current_context().parent
    return flag or bool(parent is not None and parent.params.get("include_hidden"))
