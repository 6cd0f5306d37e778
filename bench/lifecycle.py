"""What a lifecycle transition costs: change_state round trips against get_state round trips.

A managed node in a child process; this process calls its ``change_state`` (configure, then
cleanup, alternately: each runs the callback, publishes two transition events and answers)
and, interleaved, its ``get_state`` (the plainest service of the node: the baseline). Prints
the median and p99 of both in microseconds and their ratio, measured in the same run.

    python bench/lifecycle.py [--rounds N]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from _harness import BENCH_DOMAIN, finish, spawn

NODE = """
import rosl
from rosl.node.lifecycle import LifecycleNode
rosl.init([])
node = LifecycleNode("bench_managed")
print("ready", flush=True)
rosl.spin(node)
"""


def measure(rounds: int) -> tuple[list[float], list[float]]:
    import rosl
    from rosl.idl.registry import get_service_class

    rosl.init([])
    node = rosl.Node("bench_manager")
    change = node.create_client(get_service_class("lifecycle_msgs/srv/ChangeState"),
                                "/bench_managed/change_state")  # fmt: skip
    get = node.create_client(get_service_class("lifecycle_msgs/srv/GetState"),
                             "/bench_managed/get_state")  # fmt: skip
    for client in (change, get):
        if not client.wait_for_service(timeout_sec=20.0):
            raise SystemExit(f"{client.srv_name} never appeared")
    transitions, states = [], []
    for index in range(rounds):
        request = change.srv_type.Request()
        request.transition.id = 1 if index % 2 == 0 else 2  # configure, cleanup
        started = time.perf_counter()
        assert change.call(request, timeout_sec=10.0).success
        transitions.append(time.perf_counter() - started)
        started = time.perf_counter()
        get.call(get.srv_type.Request(), timeout_sec=10.0)
        states.append(time.perf_counter() - started)
    rosl.shutdown()
    return transitions, states


def p99(values: list[float]) -> float:
    return sorted(values)[int(len(values) * 0.99) - 1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=400)
    args = parser.parse_args()
    os.environ["ROSL_DOMAIN_ID"] = str(BENCH_DOMAIN)
    child = spawn(["-c", NODE])
    try:
        transitions, states = measure(args.rounds)
    finally:
        child.terminate()
        finish(child)
    t_med, s_med = statistics.median(transitions), statistics.median(states)
    print(f"rounds: {args.rounds}")
    print(f"change_state: median {t_med * 1e6:8.0f} us  p99 {p99(transitions) * 1e6:8.0f} us")
    print(f"get_state:    median {s_med * 1e6:8.0f} us  p99 {p99(states) * 1e6:8.0f} us")
    print(f"ratio change_state / get_state (median): {t_med / s_med:.2f}")


if __name__ == "__main__":
    main()
