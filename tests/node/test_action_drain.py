"""The feedback an action client runs itself before a result keeps to its callback group.

``Subscription.drain`` (the action client's feedback before its result, tf2's blocking
lookups) runs a subscription's callbacks outside of the executor; under a
``MultiThreadedExecutor`` it must not run them while an executor thread runs a callback of the
same mutually exclusive group, and inside a callback of that group it runs them at once.
"""

from __future__ import annotations

import sys
import threading
import time
from typing import TYPE_CHECKING, Any

from tests.node.action_programs import RUN_AS_RCLPY, write

if TYPE_CHECKING:
    from pathlib import Path

BOUND = 30.0  # seconds: only a broken implementation waits this long

# Publishes its feedback only once the test says "go" (so the client has its goal handle and
# asked for the result by then), all of it at once, then the result.
BURST_SERVER = """
import threading
import time

import rclpy
from rclpy.action import ActionServer
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Empty

from example_interfaces.action import Fibonacci


class BurstServer(Node):
    def __init__(self):
        super().__init__("burst_server")
        self.go = threading.Event()
        group = ReentrantCallbackGroup()
        self.create_subscription(Empty, "go", lambda _: self.go.set(), 10, callback_group=group)
        self._server = ActionServer(self, Fibonacci, "fibonacci", execute_callback=self.execute,
                                    callback_group=group)
        print("ready", flush=True)

    def execute(self, goal_handle):
        if not self.go.wait(60):
            print("never told to go", flush=True)
        feedback = Fibonacci.Feedback()
        feedback.sequence = [0, 1]
        for i in range(1, goal_handle.request.order):
            feedback.sequence.append(feedback.sequence[i] + feedback.sequence[i - 1])
            goal_handle.publish_feedback(feedback)
        time.sleep(0.5)  # (only so the feedback is received before the result)
        goal_handle.succeed()
        print("succeeded", flush=True)
        return Fibonacci.Result(sequence=feedback.sequence)


rclpy.init()
rclpy.spin(BurstServer(), executor=MultiThreadedExecutor())
"""


def _server(spawn: Any, tmp_path: Path) -> Any:
    child = spawn.command(
        [sys.executable, "-c", RUN_AS_RCLPY, write(tmp_path, "burst_server.py", BURST_SERVER)]
    )
    child.expect("^ready$")
    return child


def test_feedback_run_before_a_result_never_overlaps_a_feedback_callback_of_its_group(
    ros: Any, spawn: Any, tmp_path: Path
) -> None:
    from example_interfaces.action import Fibonacci

    from rosl.compat.rclpy.action import ActionClient
    from rosl.executor import MultiThreadedExecutor
    from rosl.idl.registry import get_message_class

    served = _server(spawn, tmp_path)
    node = ros.Node("drain_tester")
    client = ActionClient(node, Fibonacci, "fibonacci")  # the node's mutually exclusive group
    empty = get_message_class("std_msgs/msg/Empty")
    go = node.create_publisher(empty, "go", 10)
    assert client.wait_for_server(timeout_sec=BOUND), "the server never appeared in the graph"

    lock = threading.Lock()
    running = 0
    overlaps: list[int] = []
    heard: list[list[int]] = []
    result: Any = None

    def feedback(message: Any) -> None:
        nonlocal running
        with lock:
            running += 1
            if running > 1:
                overlaps.append(running)
            first = not heard
            heard.append(list(message.feedback.sequence))
        try:
            if first:  # hold the group while the result comes in with feedback still queued
                deadline = time.monotonic() + BOUND
                while not (result is not None and result.done()) and time.monotonic() < deadline:
                    time.sleep(0.01)
                time.sleep(0.5)  # (room for the client's handling of the result to overlap)
        finally:
            with lock:
                running -= 1

    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    try:
        sent = client.send_goal_async(Fibonacci.Goal(order=8), feedback_callback=feedback)
        assert sent.wait(BOUND), "no goal response"
        handle = sent.result()
        assert handle.accepted
        result = handle.get_result_async()
        assert go.wait_for_subscribers(1, BOUND) >= 1
        go.publish(empty())
        assert result.wait(BOUND), served.text
        deadline = time.monotonic() + BOUND
        while len(heard) < 7 and time.monotonic() < deadline:
            time.sleep(0.02)
    finally:
        executor.shutdown(timeout_sec=BOUND)
        spinner.join(BOUND)

    assert result.result().status == 4  # SUCCEEDED
    served.expect("^succeeded$")
    assert overlaps == []  # no two runs of the feedback callback at once
    assert heard[-1] == [0, 1, 1, 2, 3, 5, 8, 13, 21]
    assert len(heard) == 7  # none lost on the way


def test_send_goal_in_a_callback_runs_the_feedback_of_the_callbacks_own_group_first(
    ros: Any, spawn: Any, tmp_path: Path
) -> None:
    from example_interfaces.action import Fibonacci

    from rosl.compat.rclpy.action import ActionClient
    from rosl.executor import SingleThreadedExecutor
    from rosl.idl.registry import get_message_class

    _server(spawn, tmp_path)
    node = ros.Node("drain_tester")
    client = ActionClient(node, Fibonacci, "fibonacci")
    empty = get_message_class("std_msgs/msg/Empty")
    go = node.create_publisher(empty, "go", 10)
    assert client.wait_for_server(timeout_sec=BOUND), "the server never appeared in the graph"
    assert go.wait_for_subscribers(1, BOUND) >= 1
    heard: list[list[int]] = []
    outcome: list[tuple[Any, list[list[int]]]] = []

    def tick() -> None:  # a timer of the node's default group, as the feedback subscription
        timer.cancel()
        go.publish(empty())
        result = client.send_goal(
            Fibonacci.Goal(order=5),
            feedback_callback=lambda m: heard.append(list(m.feedback.sequence)),
        )
        outcome.append((result, list(heard)))  # what had run when send_goal returned

    timer = node.create_timer(0.01, tick)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    deadline = time.monotonic() + BOUND
    while not outcome and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.1)
    executor.shutdown()

    assert outcome, "send_goal never returned"
    result, before_return = outcome[0]
    assert result.status == 4
    assert before_return[-1] == [0, 1, 1, 2, 3, 5]  # its feedback ran inside the callback
    assert len(before_return) == 4
