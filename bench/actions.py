"""An action goal's round trip against a service call's, between two processes.

One child serves both ``/fibonacci`` (an action whose execute callback succeeds at once, no
feedback) and ``/add_two_ints`` (a service). The parent, in the same run, times N service
calls (the baseline: one request, one response) and N goals (send_goal, its response, the
status updates, get_result and its response), each waited for with spin_until_future_complete.
Prints the medians in microseconds and the ratio goal / call (two round trips and two status
publications per goal). Results are kept 0.05 s (``result_timeout``), so the status array
stays short; with rclpy's default of 900 s it lists every goal of the last 15 minutes and
grows with them, as in ROS 2.

    python bench/actions.py [--rounds N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

from _harness import BENCH_DOMAIN, finish, spawn

import rosl
from rosl.node.action_client import ActionClient

SERVER = """
import rosl
from rosl.node.action_server import ActionServer
from example_interfaces.action import Fibonacci
from example_interfaces.srv import AddTwoInts

rosl.init()
node = rosl.Node("bench_server")

def execute(goal_handle):
    goal_handle.succeed()
    return Fibonacci.Result(sequence=[0, 1])

def add(request, response):
    response.sum = request.a + request.b
    return response

ActionServer(node, Fibonacci, "fibonacci", execute, result_timeout=0.05)
node.create_service(AddTwoInts, "add_two_ints", add)
print("ready", flush=True)
rosl.spin(node)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=300)
    args = parser.parse_args()
    os.environ["ROSL_DOMAIN_ID"] = str(BENCH_DOMAIN)
    child = spawn(["-c", SERVER])
    from example_interfaces.action import Fibonacci  # served by rosl's import hook
    from example_interfaces.srv import AddTwoInts

    rosl.init()
    try:
        node = rosl.Node("bench_client")
        client = node.create_client(AddTwoInts, "add_two_ints")
        actions = ActionClient(node, Fibonacci, "fibonacci")
        assert client.wait_for_service(20.0)
        assert actions.wait_for_server(20.0)
        calls, goals = [], []
        for _ in range(args.rounds):
            start = time.perf_counter()
            future = client.call_async(AddTwoInts.Request(a=1, b=2))
            rosl.spin_until_future_complete(node, future, timeout_sec=10.0)
            calls.append(time.perf_counter() - start)
            start = time.perf_counter()
            sent = actions.send_goal_async(Fibonacci.Goal(order=1))
            rosl.spin_until_future_complete(node, sent, timeout_sec=10.0)
            result = sent.result().get_result_async()
            rosl.spin_until_future_complete(node, result, timeout_sec=10.0)
            assert result.result().status == 4
            goals.append(time.perf_counter() - start)
    finally:
        rosl.shutdown()
        child.terminate()
        finish(child)
    call_us = statistics.median(calls) * 1e6
    goal_us = statistics.median(goals) * 1e6
    print(f"service call (baseline): median {call_us:8.0f} us over {args.rounds}")
    print(f"action goal + result:    median {goal_us:8.0f} us over {args.rounds}")
    print(f"ratio goal / call: {goal_us / call_us:.2f}")


if __name__ == "__main__":
    sys.exit(main())
