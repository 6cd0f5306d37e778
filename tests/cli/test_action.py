"""``rosl action`` against a running Fibonacci server, in ros2action's words; actions in the
interface, node and topic commands."""

from __future__ import annotations

import re
import signal
import sys
from typing import TYPE_CHECKING

import pytest
import yaml

from rosl.graph.records import PUBLISHER
from tests.cli.conftest import Result, assert_user_error, run, wait_graph
from tests.node.action_programs import RUN_AS_RCLPY, SERVER, write

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.conftest import Processes

FEEDBACK = "/fibonacci/_action/feedback"
TYPE = "example_interfaces/action/Fibonacci"


@pytest.fixture
def fibonacci(processes: Processes, tmp_path: Path) -> None:
    """The Fibonacci action server of the node tests, as an rclpy program."""
    path = write(tmp_path, "fibonacci_server.py", SERVER)
    processes.start([sys.executable, "-c", RUN_AS_RCLPY, path, "--delay", "0.05"])
    wait_graph(lambda g: g.count(PUBLISHER, FEEDBACK) == 1)


def send_goal_output(order: int, feedback: int = 0) -> list[str | re.Pattern[str]]:
    """ros2 action send_goal's lines for a Fibonacci goal (as ros2action's own test builds them)."""
    lines: list[str | re.Pattern[str]] = [
        "Waiting for an action server to become available...",
        "Sending goal:",
        f"     order: {order}",
        "",
        re.compile("Goal accepted with ID: [a-f0-9]{32}"),
        "",
    ]
    sequence = [0, 1]
    for _ in range(order - 1):
        sequence.append(sequence[-1] + sequence[-2])
        if feedback > 0:
            lines += ["Feedback:", *("    " + yaml.dump({"sequence": sequence})).splitlines(), ""]
            feedback -= 1
    lines += ["Result:", *("    " + yaml.dump({"sequence": sequence})).splitlines(), ""]
    lines.append("Goal finished with status: SUCCEEDED")
    return lines


def matches(expected: list[str | re.Pattern[str]], text: str) -> bool:
    got = text.splitlines()
    return len(got) == len(expected) and all(
        e.fullmatch(g) if isinstance(e, re.Pattern) else e == g
        for e, g in zip(expected, got, strict=True)
    )


def test_list_prints_the_action_with_types_and_count_as_ros2(fibonacci, processes) -> None:
    assert run(processes, "action", "list") == Result(0, "/fibonacci\n", "")
    assert run(processes, "action", "list", "-t") == Result(0, f"/fibonacci [{TYPE}]\n", "")
    assert run(processes, "action", "list", "-c") == Result(0, "1\n", "")


def test_info_names_the_server_node_as_ros2(fibonacci, processes) -> None:
    plain = "Action: /fibonacci\nAction clients: 0\nAction servers: 1\n    /fibonacci_server\n"
    typed = plain.replace("/fibonacci_server\n", f"/fibonacci_server [{TYPE}]\n")
    counted = "Action: /fibonacci\nAction clients: 0\nAction servers: 1\n"

    assert run(processes, "action", "info", "/fibonacci") == Result(0, plain, "")
    assert run(processes, "action", "info", "-t", "/fibonacci") == Result(0, typed, "")
    assert run(processes, "action", "info", "-c", "/fibonacci") == Result(0, counted, "")


def test_info_of_no_action_says_zero_of_each_as_ros2(processes) -> None:
    expected = "Action: /not_an_action\nAction clients: 0\nAction servers: 0\n"
    assert run(processes, "action", "info", "/not_an_action") == Result(0, expected, "")


def test_type_prints_the_type_and_exits_1_for_an_unknown_action(fibonacci, processes) -> None:
    assert run(processes, "action", "type", "/fibonacci") == Result(0, f"{TYPE}\n", "")
    assert run(processes, "action", "type", "/not_an_action") == Result(1, "", "")


def test_send_goal_prints_ros2s_lines(fibonacci, processes) -> None:
    result = run(processes, "action", "send_goal", "/fibonacci", TYPE, "{order: 5}")

    assert result.code == 0, result
    assert matches(send_goal_output(5), result.out), result.out


def test_send_goal_with_feedback_prints_each_feedback(fibonacci, processes) -> None:
    result = run(processes, "action", "send_goal", "-f", "/fibonacci", TYPE, "{order: 5}")

    assert result.code == 0, result
    assert matches(send_goal_output(5, feedback=4), result.out), result.out


def test_send_goal_of_a_rejected_goal_says_so(fibonacci, processes) -> None:
    result = run(processes, "action", "send_goal", "/fibonacci", TYPE, "{order: -1}")

    assert result.code == 0, result
    assert result.out.splitlines()[-1] == "Goal was rejected."


def test_send_goal_with_no_server_gives_up_in_one_line(processes) -> None:
    result = run(
        processes, "action", "send_goal", "--timeout", "1", "/fibonacci", TYPE, "{order: 5}"
    )

    assert result.out == "Waiting for an action server to become available...\n"
    assert_user_error(result, "action server /fibonacci", "not available after 1.0 s")


@pytest.mark.parametrize(
    ("goal", "fragments"),
    [
        ("{order: [", ("goal values are not valid YAML",)),
        ("{ordr: 5}", ("no field 'ordr'", "did you mean 'order'")),
        ("{order: big}", ("order",)),
    ],
    ids=["not-yaml", "unknown-field", "bad-value"],
)
def test_send_goal_with_a_bad_goal_fails_in_one_line(
    rosl: Callable[..., Result], goal: str, fragments: tuple[str, ...]
) -> None:
    assert_user_error(rosl("action", "send_goal", "/fibonacci", TYPE, goal), *fragments)


def test_send_goal_with_an_unknown_type_fails_in_one_line(rosl: Callable[..., Result]) -> None:
    result = rosl("action", "send_goal", "/fibonacci", "example_interfaces/action/Fibonaci")
    assert_user_error(result, "unknown type", "did you mean 'Fibonacci'")


def test_node_info_lists_action_servers_and_hides_their_topics(fibonacci, processes) -> None:
    out = run(processes, "node", "info", "/fibonacci_server").out

    assert f"  Action Servers:\n    /fibonacci: {TYPE}\n  Action Clients:\n\n" in out
    assert "_action" not in out
    hidden = run(processes, "node", "info", "--include-hidden", "/fibonacci_server").out
    assert f"    {FEEDBACK}: {TYPE}_FeedbackMessage" in hidden
    assert f"    /fibonacci/_action/send_goal: {TYPE}_SendGoal" in hidden


def test_action_topics_and_services_are_hidden_as_in_ros2(fibonacci, processes) -> None:
    assert "_action" not in run(processes, "topic", "list").out
    assert "_action" not in run(processes, "service", "list").out
    topics = run(processes, "topic", "list", "-t", "--include-hidden-topics").out.splitlines()
    services = run(processes, "service", "list", "-t", "--include-hidden-services").out
    assert f"{FEEDBACK} [{TYPE}_FeedbackMessage]" in topics
    assert "/fibonacci/_action/status [action_msgs/msg/GoalStatusArray]" in topics
    assert f"/fibonacci/_action/send_goal [{TYPE}_SendGoal]" in services.splitlines()
    assert f"/fibonacci/_action/get_result [{TYPE}_GetResult]" in services.splitlines()
    assert "/fibonacci/_action/cancel_goal [action_msgs/srv/CancelGoal]" in services.splitlines()


def test_interface_show_prints_the_action_file(rosl: Callable[..., Result]) -> None:
    result = rosl("interface", "show", TYPE)

    assert result.code == 0
    lines = [line for line in result.out.splitlines() if not line.startswith("#")]
    assert lines == ["int32 order", "---", "int32[] sequence", "---", "int32[] sequence"]


def test_interface_proto_of_an_action_is_its_goal(rosl: Callable[..., Result]) -> None:
    assert rosl("interface", "proto", TYPE) == Result(0, '"order: 0\n"\n', "")


def test_interface_lists_include_actions(rosl: Callable[..., Result]) -> None:
    assert f"    {TYPE}" in rosl("interface", "list", "-a").out.splitlines()
    assert TYPE in rosl("interface", "package", "example_interfaces").out.splitlines()
    assert "example_interfaces" in rosl("interface", "packages", "-a").out.splitlines()


def test_ctrl_c_during_send_goal_cancels_the_goal_on_the_server(fibonacci, processes) -> None:
    from tests.conftest import ChildOutput, wait_until

    child = processes.rosl(
        "action", "send_goal", "/fibonacci", TYPE, "{order: 60}", env={"NO_COLOR": "1"}
    )
    output = ChildOutput(child)

    def accepted() -> bool:
        output.pump()
        return "Goal accepted with ID" in output.text["out"]

    assert wait_until(accepted, timeout=30.0), output.text
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=30)
    text = output.text["out"] + out

    assert text.splitlines()[-2:] == ["Canceling goal...", "Goal canceled."], text + err
    assert child.returncode == 130


CLIENT_NODE = """
import rosl
from example_interfaces.action import Fibonacci
from rosl.compat.rclpy.action import ActionClient

rosl.init()
node = rosl.Node("fib_client")
client = ActionClient(node, Fibonacci, "fibonacci")
rosl.spin(node)
"""


def test_an_action_client_shows_in_node_info_and_action_info(fibonacci, processes) -> None:
    from rosl.graph.records import SUBSCRIPTION

    processes.python(CLIENT_NODE)
    wait_graph(lambda g: g.count(SUBSCRIPTION, FEEDBACK) == 1)

    out = run(processes, "node", "info", "/fib_client").out
    info = run(processes, "action", "info", "/fibonacci").out

    assert out.endswith(f"  Action Servers:\n\n  Action Clients:\n    /fibonacci: {TYPE}\n")
    assert "Action clients: 1\n    /fib_client\nAction servers: 1\n" in info
