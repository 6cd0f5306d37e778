"""CLI start-up: wall time of everyday `rosl` commands vs the interpreter starting (`-c pass`).

Each command runs as a fresh process, as a user would type it, median of --runs runs,
interleaved round-robin so machine noise hits every row alike:

  python -c pass                           the baseline: the same interpreter, doing nothing
  rosl --help                              click + the command table
  rosl interface show std_msgs/msg/String  reading a .msg file (no build, no daemon)
  rosl topic list                          a new process discovering the graph (a talker runs)
  rosl topic echo /chatter --once          discover, subscribe, first message of a 10 Hz talker

Prints median and min in ms, and the ratio of the median over the baseline's median. For
context only (not measured here): with ros2cli, `ros2 topic list` typically takes ~0.5-1 s
(Python start-up, rclpy, and either the daemon round trip or DDS discovery without it), and
`ros2 topic echo --once` on a 10 Hz topic about as long plus up to one period.

    python bench/cli_startup.py [--runs N]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

from _harness import BENCH_DOMAIN, spawn
from _procs import bench_env, rosl_cmd, stop

DOMAIN = BENCH_DOMAIN + 1


def talker() -> None:
    import rosl

    String = rosl.get_interface("std_msgs/msg/String")  # noqa: N806
    rosl.init([], domain_id=DOMAIN)
    node = rosl.Node("talker")
    pub = node.create_publisher(String, "/chatter", 10)
    count = [0]

    def tick() -> None:
        count[0] += 1
        pub.publish(String(data=f"hello {count[0]}"))

    node.create_timer(0.1, tick)
    print("ready", flush=True)
    rosl.spin(node)  # until the parent's SIGTERM
    rosl.shutdown()


def rows() -> list[tuple[str, list[str], str]]:
    """(label, argv, text the output must contain)."""
    rosl = rosl_cmd()
    return [
        ("python -c pass", [sys.executable, "-c", "pass"], ""),
        ("rosl --help", [*rosl, "--help"], "Commands:"),
        (
            "rosl interface show std_msgs/msg/String",
            [*rosl, "interface", "show", "std_msgs/msg/String"],
            "string data",
        ),
        ("rosl topic list", [*rosl, "topic", "list"], "/chatter"),
        (
            "rosl topic echo /chatter --once",
            [*rosl, "topic", "echo", "/chatter", "--once"],
            "data:",
        ),
    ]


def timed(argv: list[str], expect: str, env: dict[str, str]) -> tuple[float, bool]:
    start = time.perf_counter()
    try:
        out = subprocess.run(argv, capture_output=True, text=True, timeout=30, env=env)
    except subprocess.TimeoutExpired:
        return time.perf_counter() - start, False
    seconds = time.perf_counter() - start
    return seconds, out.returncode == 0 and expect in out.stdout


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=11)
    args = parser.parse_args()
    env = bench_env(DOMAIN)
    table = rows()
    times: dict[str, list[float]] = {label: [] for label, _, _ in table}
    failed: dict[str, int] = dict.fromkeys(times, 0)
    child = spawn([__file__, "talker"])
    try:
        time.sleep(1.0)  # the talker announced itself and publishes
        for run in range(args.runs + 1):
            shift = run % len(table)
            for label, argv, expect in table[shift:] + table[:shift]:
                seconds, ok = timed(argv, expect, env)
                if run == 0:
                    continue  # warm-up round: page cache, .pyc files
                times[label].append(seconds)
                failed[label] += not ok
    finally:
        stop(child)
    base = statistics.median(times["python -c pass"])
    print(f"fresh processes, median of {args.runs} runs each (plus one warm-up round)")
    print(f"{'command':42} {'median ms':>10} {'min ms':>8} {'ratio':>7} {'failed':>7}")
    for label, values in times.items():
        median = statistics.median(values)
        print(
            f"{label:42} {median * 1000:>10.1f} {min(values) * 1000:>8.1f} "
            f"{median / base:>6.1f}x {failed[label]:>7}"
        )
    print("ratio = median / median of `python -c pass` (same interpreter, same run)")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "talker":
        talker()
    else:
        main()
