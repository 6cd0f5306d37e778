"""Actions across processes: rclpy-style servers and clients, cancel, status, result expiry."""

from __future__ import annotations

import sys
import time
from typing import TYPE_CHECKING, Any

import pytest

from tests.node.action_programs import (
    CANCELLING_CLIENT,
    CLIENT,
    QUEUE_SERVER,
    RUN_AS_RCLPY,
    SERVER,
    TUTORIAL_CLIENT,
    TUTORIAL_SERVER,
    write,
)
from tests.node.helpers import spin_until

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.node.helpers import Child

SUCCEEDED, CANCELED, UNKNOWN = 4, 5, 0


@pytest.fixture
def server(spawn: Any, tmp_path: Path) -> Callable[..., Child]:
    """Start the Fibonacci server with options (``--executor single``, ``--cancel reject``...)."""
    path = write(tmp_path, "fibonacci_server.py", SERVER)

    def start(*options: str) -> Child:
        child = spawn.command([sys.executable, "-c", RUN_AS_RCLPY, path, *options])
        child.expect("^ready$")
        return child

    return start


def _client(ros: Any) -> tuple[Any, Any, Any]:
    from example_interfaces.action import Fibonacci

    from rosl.compat.rclpy.action import ActionClient

    node = ros.Node("action_tester")
    client = ActionClient(node, Fibonacci, "fibonacci")
    assert client.wait_for_server(timeout_sec=20.0), "the server never appeared in the graph"
    return node, client, Fibonacci


def _wait(node: Any, future: Any, timeout: float = 20.0) -> Any:
    assert spin_until(node, future.done, timeout), "no answer in time"
    return future.result()


def test_minimal_client_gets_feedback_and_the_result_from_a_coroutine_server(
    server: Any, spawn: Any, tmp_path: Path
) -> None:
    served = server("--delay", "0.02")
    client = spawn.command(
        [sys.executable, "-c", RUN_AS_RCLPY, write(tmp_path, "client.py", CLIENT)]
    )

    client.expect(r"^Goal accepted :\)$")
    client.expect(r"^Received feedback: \[0, 1, 1\]$")
    client.expect(r"^Received feedback: \[0, 1, 1, 2, 3, 5, 8, 13, 21, 34, 55\]$")
    client.expect(r"^Goal succeeded! Result: \[0, 1, 1, 2, 3, 5, 8, 13, 21, 34, 55\]$")
    client.finish()
    assert client.returncode == 0
    served.expect(r"^goal request: order 10$")


def test_a_client_cancels_a_running_goal_and_the_server_stops_it(
    server: Any, spawn: Any, tmp_path: Path
) -> None:
    served = server("--delay", "0.2")
    client = spawn.command(
        [sys.executable, "-c", RUN_AS_RCLPY, write(tmp_path, "cancel.py", CANCELLING_CLIENT)]
    )

    client.expect("^Canceling goal$")
    client.expect("^Goal successfully canceled$")
    served.expect("^cancel request$")
    served.expect("^goal canceled$")
    client.finish()
    assert client.returncode == 0


def test_the_action_tutorials_server_and_client_run_unchanged(spawn: Any, tmp_path: Path) -> None:
    server = spawn.command(
        [sys.executable, "-c", RUN_AS_RCLPY, write(tmp_path, "server.py", TUTORIAL_SERVER)]
    )
    server.expect("^ready$")
    client = spawn.command(
        [sys.executable, "-c", RUN_AS_RCLPY, write(tmp_path, "client.py", TUTORIAL_CLIENT)]
    )

    client.expect(r"^Received feedback: array\('i', \[0, 1, 1\]\)$")
    client.expect(r"^Received feedback: array\('i', \[0, 1, 1, 2, 3, 5\]\)$")
    client.expect(r"^Result: array\('i', \[0, 1, 1, 2, 3, 5\]\)$")
    client.finish()
    assert client.returncode == 0
    server.expect(r"Feedback: array\('i', \[0, 1, 1, 2, 3, 5\]\)$", stream="err")


def test_an_accepted_callback_queues_goals_that_wait_in_the_accepted_state(
    ros: Any, spawn: Any, tmp_path: Path
) -> None:
    from rosl.idl.registry import get_message_class
    from rosl.node.qos import DurabilityPolicy, QoSProfile

    queue = spawn.command(
        [sys.executable, "-c", RUN_AS_RCLPY, write(tmp_path, "queue.py", QUEUE_SERVER)]
    )
    queue.expect("^ready$")
    node, client, fibonacci = _client(ros)
    arrays: list[dict[bytes, int]] = []
    node.create_subscription(
        get_message_class("action_msgs/msg/GoalStatusArray"), "/fibonacci/_action/status",
        lambda msg: arrays.append(
            {bytes(s.goal_info.goal_id.uuid): int(s.status) for s in msg.status_list}
        ),
        QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL),
    )  # fmt: skip

    first = _wait(node, client.send_goal_async(fibonacci.Goal(order=6)))
    # the server calls the accepted callback after answering (as rclpy's): wait for it, or the
    # second goal's could come first
    queue.expect("^executing order 6$")
    second = _wait(node, client.send_goal_async(fibonacci.Goal(order=3)))
    results = [_wait(node, first.get_result_async()), _wait(node, second.get_result_async())]
    ids = (bytes(first.goal_id.uuid), bytes(second.goal_id.uuid))
    assert spin_until(node, lambda: {ids[0]: 4, ids[1]: 4} in arrays, 10.0), arrays

    assert [r.status for r in results] == [SUCCEEDED, SUCCEEDED]
    assert list(results[1].result.sequence) == [0, 1, 1, 2]
    # the second goal waited, ACCEPTED, until the first ended; they never ran together
    assert {ids[0]: SUCCEEDED, ids[1]: 1} in arrays, arrays
    assert not [a for a in arrays if a.get(ids[0]) == 2 and a.get(ids[1]) == 2]
    queue.expect("^executing order 3$")
    assert queue.count("^executing order 6$") == queue.count("^queued order 3$") == 1


def test_a_rejected_goal_has_no_result(ros: Any, server: Any) -> None:
    served = server()
    node, client, fibonacci = _client(ros)

    handle = _wait(node, client.send_goal_async(fibonacci.Goal(order=-1)))

    assert not handle.accepted
    with pytest.raises(TypeError, match="rejected"):
        handle.get_result_async()
    served.expect("^goal request: order -1$")


def test_a_goal_callback_that_raises_fails_the_goal_request_at_once(ros: Any, server: Any) -> None:
    from rosl.node.client import ServiceFailedError

    served = server()
    node, client, fibonacci = _client(ros)
    sent = client.send_goal_async(fibonacci.Goal(order=99))

    assert spin_until(node, sent.done, 20.0), "the goal request was never answered"
    assert isinstance(sent.exception(), ServiceFailedError)
    assert "RuntimeError: no goals of order 99" in str(sent.exception())
    served.expect("no goals of order 99", stream="err")
    assert _wait(node, client.send_goal_async(fibonacci.Goal(order=2))).accepted  # still serving


def test_a_cancel_the_server_refuses_leaves_the_goal_running(ros: Any, server: Any) -> None:
    served = server("--cancel", "reject", "--hold", "until-cancel", "--delay", "0")
    node, client, fibonacci = _client(ros)
    handle = _wait(node, client.send_goal_async(fibonacci.Goal(order=12)))

    answer = _wait(node, handle.cancel_goal_async())
    result = _wait(node, handle.get_result_async())

    assert answer.return_code == answer.ERROR_REJECTED
    assert len(answer.goals_canceling) == 0
    assert result.status == SUCCEEDED
    assert list(result.result.sequence)[-1] == 144
    served.expect("^cancel request$")


def test_cancel_answers_name_unknown_and_finished_goals(ros: Any, server: Any) -> None:
    server("--delay", "0")
    node, client, fibonacci = _client(ros)
    handle = _wait(node, client.send_goal_async(fibonacci.Goal(order=2)))
    assert _wait(node, handle.get_result_async()).status == SUCCEEDED

    finished = _wait(node, handle.cancel_goal_async())
    stranger = client._cancel_request(handle)
    stranger.goal_info.goal_id.uuid = bytes(range(1, 17))
    unknown = _wait(node, client._cancel_client.call_async(stranger))

    assert finished.return_code == finished.ERROR_GOAL_TERMINATED
    assert unknown.return_code == unknown.ERROR_UNKNOWN_GOAL_ID


def test_the_status_array_follows_a_goal_and_a_late_subscriber_gets_the_last_one(
    ros: Any, server: Any
) -> None:
    from rosl.idl.registry import get_message_class
    from rosl.node.qos import DurabilityPolicy, QoSProfile, qos_profile_action_status_default

    server("--delay", "0.05")
    node, client, fibonacci = _client(ros)
    status_type = get_message_class("action_msgs/msg/GoalStatusArray")
    seen: list[list[int]] = []
    node.create_subscription(
        status_type, "/fibonacci/_action/status",
        lambda msg: seen.append([int(s.status) for s in msg.status_list]),
        QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL),  # keeps every one
    )  # fmt: skip
    handle = _wait(node, client.send_goal_async(fibonacci.Goal(order=5)))
    _wait(node, handle.get_result_async())
    assert spin_until(node, lambda: [SUCCEEDED] in seen, 10.0), seen

    late: list[Any] = []
    node.create_subscription(
        status_type, "/fibonacci/_action/status", late.append, qos_profile_action_status_default
    )
    assert spin_until(node, lambda: bool(late), 10.0), "no status for a late subscriber"

    assert [2] in seen  # EXECUTING was published before SUCCEEDED
    assert seen.index([2]) < seen.index([SUCCEEDED])
    assert [int(s.status) for s in late[-1].status_list] == [SUCCEEDED]
    assert bytes(late[-1].status_list[0].goal_info.goal_id.uuid) == bytes(handle.goal_id.uuid)
    assert handle.status == SUCCEEDED


def test_a_result_is_kept_until_the_goal_expires(ros: Any, server: Any) -> None:
    from rosl.idl.registry import get_message_class
    from rosl.node.qos import qos_profile_action_status_default

    # the second request must come within the result timeout: a machine too slow for 5 s
    # (it took longer from sending the goal) gets the whole check again with 60 s
    for lease in (5.0, 60.0):
        served = server("--result-timeout", str(lease), "--delay", "0")
        node, client, fibonacci = _client(ros)
        arrays: list[Any] = []
        node.create_subscription(
            get_message_class("action_msgs/msg/GoalStatusArray"), "/fibonacci/_action/status",
            arrays.append, qos_profile_action_status_default,
        )  # fmt: skip
        started = time.monotonic()
        handle = _wait(node, client.send_goal_async(fibonacci.Goal(order=3)))
        first = _wait(node, handle.get_result_async())
        again = _wait(node, handle.get_result_async())  # still kept: the same answer
        if time.monotonic() - started < lease:
            break
        node.destroy_node()
        served.stop()
    assert spin_until(node, lambda: bool(arrays) and not arrays[-1].status_list, lease + 20.0), (
        "the goal never expired"
    )

    expired = _wait(node, client._result_client.call_async(
        fibonacci.Impl.GetResultService.Request(goal_id=handle.goal_id)
    ))  # fmt: skip

    assert first.status == again.status == SUCCEEDED
    assert list(again.result.sequence) == [0, 1, 1, 2]
    assert expired.status == UNKNOWN


@pytest.mark.parametrize("execute", ["plain", "awaiting"])
def test_a_single_threaded_server_with_a_plain_or_an_awaiting_execute_callback(
    ros: Any, server: Any, execute: str
) -> None:
    served = server("--executor", "single", "--execute", execute, "--delay", "0")
    node, client, fibonacci = _client(ros)
    feedback: list[list[int]] = []

    handle = _wait(
        node,
        client.send_goal_async(
            fibonacci.Goal(order=4), lambda msg: feedback.append(list(msg.feedback.sequence))
        ),
    )
    result = _wait(node, handle.get_result_async())

    assert result.status == SUCCEEDED
    assert list(result.result.sequence) == [0, 1, 1, 2, 3]
    assert spin_until(node, lambda: [0, 1, 1, 2, 3] in feedback, 10.0), feedback
    assert served.count("^awaited$") == (execute == "awaiting")


def test_send_goal_blocks_until_the_result_without_spinning(ros: Any, server: Any) -> None:
    server("--delay", "0")
    _, client, fibonacci = _client(ros)

    result = client.send_goal(fibonacci.Goal(order=6))
    rejected = client.send_goal(fibonacci.Goal(order=-3))

    assert result.status == SUCCEEDED
    assert list(result.result.sequence) == [0, 1, 1, 2, 3, 5, 8]
    assert rejected is None


def test_graph_queries_name_the_action_and_its_nodes(ros: Any, server: Any) -> None:
    from rosl.compat.rclpy.action import (
        get_action_client_names_and_types_by_node,
        get_action_names_and_types,
        get_action_server_names_and_types_by_node,
    )

    server()
    node, _, _ = _client(ros)
    wanted = [("/fibonacci", ["example_interfaces/action/Fibonacci"])]

    def answers() -> list[Any]:
        return [
            get_action_names_and_types(node),
            get_action_server_names_and_types_by_node(node, "fibonacci_server", "/"),
            get_action_client_names_and_types_by_node(node, "action_tester", "/"),
            get_action_server_names_and_types_by_node(node, "action_tester", "/"),
        ]

    assert spin_until(node, lambda: answers() == [wanted, wanted, wanted, []], 20.0), answers()
