"""Executor overhead: callbacks/s through SingleThreadedExecutor vs a plain loop, idle CPU.

Part 1: a node with 10 timers (period 1 ns: always due) and 10 subscriptions, each holding
queued messages, spun by ``SingleThreadedExecutor.spin_once``; the baseline calls the same
callables (the timers' callbacks, and each subscription's decode-and-call) from a plain
Python loop. The ratio is the executor's own cost per callback.

Part 2: the CPU time an idle node with a 100 Hz timer uses, as a share of one core, over
a few seconds (rclpy: about 16 %, ROS 1: 3 %; target <= 3 %).

    python bench/executor.py [--callbacks N] [--idle SECONDS]
"""

from __future__ import annotations

import argparse
import resource
import time
from typing import Any

from _harness import BENCH_DOMAIN


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def callbacks_per_second(count: int) -> tuple[float, float]:
    """(executor callbacks/s, plain-loop callbacks/s) over the same callables."""
    import rosl

    int32 = rosl.get_interface("std_msgs/msg/Int32")
    node = rosl.Node("bench_executor")
    ran = [0]

    def callback(*_: Any) -> None:
        ran[0] += 1

    timers = [node.create_timer(1e-9, callback) for _ in range(10)]
    subs = []
    per_topic = count // 20 + 1
    for i in range(10):
        topic = f"/bench_executor_{i}"
        subs.append(node.create_subscription(int32, topic, callback, per_topic))
        publisher = node.create_publisher(int32, topic, 10)
        for n in range(per_topic):
            publisher.publish(int32(data=n))
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    deadline = time.monotonic() + 10
    while sum(len(s._queue) for s in subs) < 10 * per_topic and time.monotonic() < deadline:
        node.participant.poll(0.05)  # every message queued before timing starts
    queued = [list(s._queue) for s in subs]

    ran[0] = 0
    start = time.perf_counter()
    while ran[0] < count:
        executor.spin_once(timeout_sec=1.0)
    spun = ran[0] / (time.perf_counter() - start)

    # the baseline: the same work without an executor (timers' callbacks, decode + call)
    for sub, items in zip(subs, queued, strict=True):
        sub._queue.clear()
        sub._queue.extend(items)
    ran[0] = 0
    start = time.perf_counter()
    while ran[0] < count:
        for timer in timers:
            timer.call()
        for sub in subs:
            work = sub._take()
            if work is not None:
                work()
    plain = ran[0] / (time.perf_counter() - start)
    executor.shutdown()
    node.destroy_node()
    return spun, plain


def idle_cpu(seconds: float) -> float:
    """Share of one core used by a node whose only work is a 100 Hz timer."""
    import rosl

    node = rosl.Node("bench_idle")
    ticks = [0]
    node.create_timer(0.01, lambda: ticks.__setitem__(0, ticks[0] + 1))
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    end = time.monotonic() + 1.0
    while time.monotonic() < end:  # past start-up work (discovery, the name check)
        executor.spin_once(timeout_sec=0.1)
    cpu, wall = _cpu(), time.monotonic()
    end = wall + seconds
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.1)
    share = (_cpu() - cpu) / (time.monotonic() - wall)
    executor.shutdown()
    node.destroy_node()
    return share


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--callbacks", type=int, default=20000)
    parser.add_argument("--idle", type=float, default=5.0)
    args = parser.parse_args()
    import rosl

    rosl.init([], domain_id=BENCH_DOMAIN)
    spun, plain = callbacks_per_second(args.callbacks)
    share = idle_cpu(args.idle)
    rosl.shutdown()
    print("10 timers + 10 subscriptions, SingleThreadedExecutor.spin_once vs a plain loop")
    print(f"  executor   {spun:>10,.0f} callbacks/s")
    print(f"  plain loop {plain:>10,.0f} callbacks/s")
    print(f"  overhead ratio plain/executor: {plain / spun:.2f}")
    print(f"idle node, 100 Hz timer: {share * 100:.1f} % of a core (target <= 3 %)")


if __name__ == "__main__":
    main()
