"""``rosl topic``: list, info, type, find, echo, hz, bw, delay, pub."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import click

from rosl.cli import render
from rosl.cli.options import domain_option
from rosl.cli.options import include_hidden as hidden_flag
from rosl.introspection import echo as echo_
from rosl.introspection import monitor, qos_words, topics
from rosl.introspection import publish as publish_
from rosl.introspection.session import Session, visible

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.qos import QoSProfile

hidden_option = click.option(
    "--include-hidden-topics", "include_hidden", is_flag=True, help="Consider hidden topics as well"
)


@click.group("topic")
@hidden_option
def command(include_hidden: bool) -> None:
    """Various topic related sub-commands."""
    del include_hidden  # read by the verbs: `rosl topic --include-hidden-topics list`


def qos_options(what: str, default_profile: str) -> Callable[[Any], Any]:
    """ros2's ``--qos-profile/--qos-depth/--qos-history/--qos-reliability/--qos-durability``."""

    def choice(name: str, words: tuple[str, ...], text: str) -> Any:
        return click.option(name, type=click.Choice(words), default=None, help=text)

    def add(command: Any) -> Any:
        for decorator in reversed(
            [
                choice(
                    "--qos-profile",
                    qos_words.PROFILES,
                    f"Quality of service preset profile to {what} with "
                    f"(default: {default_profile})",
                ),
                click.option(
                    "--qos-depth",
                    type=int,
                    default=None,
                    metavar="N",
                    help=f"Queue size setting to {what} with (overrides --qos-profile)",
                ),
                choice("--qos-history", qos_words.HISTORIES, "History of samples (overrides)"),
                choice("--qos-reliability", qos_words.RELIABILITIES, "Reliability (overrides)"),
                choice("--qos-durability", qos_words.DURABILITIES, "Durability (overrides)"),
            ]
        ):
            command = decorator(command)
        return command

    return add


def _qos(
    default_profile: str,
    profile: str | None,
    depth: int | None,
    history: str | None,
    reliability: str | None,
    durability: str | None,
) -> QoSProfile | None:
    """The profile the ``--qos-*`` words ask for; None when none was given."""
    if not qos_words.given(profile, depth, history, reliability, durability):
        return None
    return qos_words.profile_from_words(
        profile or default_profile,
        reliability=reliability,
        durability=durability,
        depth=depth,
        history=history,
    )


@command.command("list")
@click.option("-t", "--show-types", is_flag=True, help="Additionally show the topic type")
@click.option(
    "-c", "--count-topics", "count", is_flag=True, help="Only display the number of topics"
)
@click.option("-v", "--verbose", is_flag=True, help="List full details about each topic")
@hidden_option
@domain_option
def list_(
    show_types: bool, count: bool, verbose: bool, include_hidden: bool, domain_id: int | None
) -> None:
    """Output a list of available topics."""
    with Session(domain_id) as session:
        render.lines(
            topics.list_topics(
                session,
                show_types=show_types,
                count=count,
                verbose=verbose,
                include_hidden=hidden_flag(include_hidden),
            )
        )


@command.command("info")
@click.argument("topic_name")
@click.option(
    "-v",
    "--verbose",
    is_flag=True,
    help="Prints detailed information like the node name, GID and QoS",
)
@click.option("--stats", is_flag=True, help="With -v: each endpoint's sent/received/lost counts")
@domain_option
def info(topic_name: str, verbose: bool, stats: bool, domain_id: int | None) -> None:
    """Print information about a topic."""
    with Session(domain_id) as session:
        render.lines(topics.topic_info(session, topic_name, verbose=verbose, stats=stats))


@command.command("type")
@click.argument("topic_name")
@hidden_option
@domain_option
def type_(topic_name: str, include_hidden: bool, domain_id: int | None) -> None:
    """Print a topic's type (an unknown or hidden one prints nothing and exits 1, as in ros2)."""
    with Session(domain_id) as session:
        types = session.graph().topics().get(topic_name)
    if not types or not visible(topic_name, hidden_flag(include_hidden)):
        raise click.exceptions.Exit(1)
    render.lines(types)


@command.command("find")
@click.argument("topic_type")
@click.option(
    "-c", "--count-topics", "count", is_flag=True, help="Only display the number of topics"
)
@hidden_option
@domain_option
def find(topic_type: str, count: bool, include_hidden: bool, domain_id: int | None) -> None:
    """Output a list of available topics of a given type."""
    with Session(domain_id) as session:
        found = topics.find_topics(session, topic_type, include_hidden=hidden_flag(include_hidden))
        render.lines([str(len(found))] if count else found)


@command.command("echo")
@click.argument("topic_name")
@click.argument("message_type", required=False)
@click.option("--once", is_flag=True, help="Print the first message received and then exit")
@click.option("--field", default=None, help="Echo a selected field of a message (e.g. 'linear.x')")
@click.option("--csv", is_flag=True, help="Output all recursive fields separated by commas")
@click.option(
    "-l",
    "--truncate-length",
    type=int,
    default=echo_.DEFAULT_TRUNCATE,
    help="Truncate strings and arrays to this length",
)
@click.option("-f", "--full-length", is_flag=True, help="Do not truncate")
@click.option("--no-arr", is_flag=True, help="Don't print array fields of messages")
@click.option("--no-str", is_flag=True, help="Don't print string fields of messages")
@click.option("--flow-style", is_flag=True, help="Print collections in the block style")
@click.option(
    "--filter", "filter_expr", default=None, help="Python expression on m to select messages"
)
@click.option(
    "--timeout",
    type=float,
    default=None,
    help="Fail if no message arrives within this many seconds",
)
@click.option(
    "-i",
    "--include-message-info",
    is_flag=True,
    help="Show the message info (timestamps, sequence)",
)
@qos_options("subscribe", "sensor_data")
@click.option("--no-lost-messages", is_flag=True, help="Don't report when a message is lost")
@click.option("--lost-messages", is_flag=True, hidden=True, help="DEPRECATED: Does nothing")
@click.option("--raw", is_flag=True, help="Echo the raw binary representation")
@domain_option
def echo(
    topic_name: str,
    message_type: str | None,
    once: bool,
    field: str | None,
    csv: bool,
    truncate_length: int,
    full_length: bool,
    no_arr: bool,
    no_str: bool,
    flow_style: bool,
    filter_expr: str | None,
    timeout: float | None,
    include_message_info: bool,
    qos_profile: str | None,
    qos_depth: int | None,
    qos_history: str | None,
    qos_reliability: str | None,
    qos_durability: str | None,
    no_lost_messages: bool,
    lost_messages: bool,
    raw: bool,
    domain_id: int | None,
) -> None:
    """Output messages from a topic."""
    if lost_messages:
        render.warn(
            "WARNING: '--lost-messages' is deprecated; lost messages are reported by default"
        )
    qos = _qos("sensor_data", qos_profile, qos_depth, qos_history, qos_reliability, qos_durability)
    options = echo_.EchoOptions(
        once=once,
        field=field,
        csv=csv,
        no_arr=no_arr,
        no_str=no_str,
        flow_style=flow_style,
        truncate_length=None if full_length else truncate_length,
        filter_expr=filter_expr,
        timeout=timeout,
        include_info=include_message_info,
        qos=qos,
        lost_messages=not no_lost_messages,
        raw=raw,
    )
    with Session(domain_id) as session:
        for block in echo_.echo(session, topic_name, message_type, options):
            render.text(block + "\n")


@command.command("hz")
@click.argument("topic_names", nargs=-1, required=True)
@click.option("-w", "--window", type=int, default=10000, help="Window size, in # of messages")
@click.option(
    "--filter",
    "filter_expr",
    default=None,
    help="Only count messages where this Python expression on m is true",
)
@click.option("--wall-time", is_flag=True, help="Accepted; rates always use receive times")
@domain_option
def hz(
    topic_names: tuple[str, ...],
    window: int,
    filter_expr: str | None,
    wall_time: bool,
    domain_id: int | None,
) -> None:
    """Print the average receiving rate (timed at the socket, no decoding)."""
    del wall_time
    with Session(domain_id) as session:
        for hint in monitor.close_names(session, list(topic_names)):
            render.warn(hint)
        for block in monitor.hz(session, list(topic_names), window, filter_expr):
            render.text(block + "\n")


@command.command("bw")
@click.argument("topic_name")
@click.option("-w", "--window", type=int, default=100, help="Window size, in # of messages")
@domain_option
def bw(topic_name: str, window: int, domain_id: int | None) -> None:
    """Display bandwidth used by a topic."""
    with Session(domain_id) as session:
        for hint in monitor.close_names(session, [topic_name]):
            render.warn(hint)
        for block in monitor.bw(session, topic_name, window):
            render.text(block + "\n")


@command.command("delay")
@click.argument("topic_name")
@click.option("-w", "--window", type=int, default=10000, help="Window size, in # of messages")
@domain_option
def delay(topic_name: str, window: int, domain_id: int | None) -> None:
    """Display delay of a topic from its header timestamp."""
    with Session(domain_id) as session:
        for block in monitor.delay(session, topic_name, window):
            render.text(block + "\n")


@command.command("pub")
@click.argument("topic_name")
@click.argument("message_type")
@click.argument("values", required=False, default="{}")
@click.option("-r", "--rate", type=float, default=1.0, help="Publishing rate in Hz (default: 1)")
@click.option(
    "-p",
    "--print",
    "print_every",
    type=int,
    default=1,
    help="Only print every N-th published message",
)
@click.option("-1", "--once", is_flag=True, help="Publish one message and exit")
@click.option(
    "-t", "--times", type=int, default=0, help="Publish this number of times and then exit"
)
@click.option(
    "-w",
    "--wait-matching-subscriptions",
    "wait_matching",
    type=int,
    default=None,
    help="Wait for this many matching subscriptions (default 1 with --once/--times)",
)
@click.option(
    "--max-wait-time-secs", "max_wait", type=float, default=5.0, help="Bound on that wait"
)
@click.option(
    "--keep-alive",
    type=float,
    default=0.1,
    help="Keep publishing node alive for N seconds after the last msg",
)
@qos_options("publish", "system_default")
@domain_option
def pub(
    topic_name: str,
    message_type: str,
    values: str,
    rate: float,
    print_every: int,
    once: bool,
    times: int,
    wait_matching: int | None,
    max_wait: float,
    keep_alive: float,
    qos_profile: str | None,
    qos_depth: int | None,
    qos_history: str | None,
    qos_reliability: str | None,
    qos_durability: str | None,
    domain_id: int | None,
) -> None:
    """Publish a message to a topic."""
    from rosl.idl.yaml_io import parse_yaml_mapping

    data = parse_yaml_mapping(values, "message values")
    options = publish_.PubOptions(
        rate=rate,
        once=once,
        times=times,
        print_every=print_every,
        wait_matching=wait_matching,
        max_wait=max_wait,
        keep_alive=keep_alive,
        qos=_qos(
            "system_default", qos_profile, qos_depth, qos_history, qos_reliability, qos_durability
        ),
    )
    with Session(domain_id) as session:
        for stream, line in publish_.publish(session, topic_name, message_type, data, options):
            (render.warn if stream == "err" else render.text)(
                line + "\n" if stream == "out" else line
            )
