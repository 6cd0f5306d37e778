"""Python work per received message of a subscription: opcodes counted, or a profile.

Publisher processes (--publishers, each a rosl node publishing a std_msgs/msg/String whose
CDR is --size bytes with a timer at --hz) feed one subscription (history depth --depth,
a callback that counts) in this process, spun as bench/fanin.py spins it
(``executor.spin_once(timeout_sec=0.05)`` in a loop). After --warmup callbacks, the next
--messages callbacks are measured on this thread (the receive path, the executor, the
deserializer, the callback; not the discovery thread):

  opcodes  every Python bytecode instruction executed (``sys.settrace`` with
           ``f_trace_opcodes``), per message, in total and by (file, function);
  profile  cProfile's table, sorted by own time.

Tracing makes the subscriber far slower than its publishers, so its socket stays full and
every poll reads as much as it may (the --depth deep queue's worth), as in a saturated
fan-in. ``ROSL_BACKLOG_MS`` is raised here so the catch-up read of a long-waiting socket
(which would fill and drop the queue) does not fire: it is the same path, once a second.
Loss is therefore the kernel's, and costs the subscriber nothing.

Opcode counts do not depend on the machine's load: run it before and after a change
(``PYTHONPATH=<other checkout> python bench/sub_opcodes.py`` measures another tree's rosl).

    python bench/sub_opcodes.py [--mode opcodes|profile] [--publishers 4] [--hz 1000]
                                [--size 64] [--depth 10] [--messages 3000] [--warmup 300]
"""

from __future__ import annotations

import argparse
import collections
import os
import subprocess
import sys
import time
from typing import Any

from _harness import BENCH_DOMAIN, lock_domain
from _procs import bench_env, stop

DOMAIN = BENCH_DOMAIN + 9
TOPIC = "/bench_sub_opcodes"
TYPE = "std_msgs/msg/String"
CDR_STRING_OVERHEAD = 9  # encapsulation (4) + length (4) + the string's NUL (1)


def publish(index: int, hz: float, size: int) -> None:
    """A child: publish at ``hz`` (in bursts of a millisecond's worth) until stdin closes."""
    import select

    import rosl

    rosl.init([], domain_id=DOMAIN)
    from std_msgs.msg import String  # (rosl's import hook, after init)

    pub = rosl.Node(f"sub_opcodes_pub_{index}").create_publisher(String, TOPIC, 10)
    msg = String(data="x" * max(0, size - CDR_STRING_OVERHEAD))
    print("ready", flush=True)
    start, sent = time.monotonic(), 0
    while not select.select([sys.stdin], [], [], 0.001)[0]:  # (no executor: cheap senders)
        due = int((time.monotonic() - start) * hz)
        while sent < due:
            pub.publish(msg)
            sent += 1
    rosl.shutdown()


class Counter:
    """Counts executed opcodes by (file, function) on the thread that installs it."""

    def __init__(self) -> None:
        self.by_code: collections.Counter[Any] = collections.Counter()
        self.by_line: collections.Counter[Any] = collections.Counter()

    def _local(self, frame: Any, event: str, arg: Any) -> Any:
        if event == "opcode":
            self.by_code[frame.f_code] += 1
            self.by_line[frame.f_code, frame.f_lineno] += 1
        return self._local

    def _global(self, frame: Any, event: str, arg: Any) -> Any:
        frame.f_trace_opcodes = True
        return self._local

    def start(self) -> None:
        sys.settrace(self._global)

    def stop(self) -> None:
        sys.settrace(None)


def _where(code: Any) -> str:
    path = code.co_filename
    for marker in ("/rosl/", "/site-packages/", "/lib/python"):
        if marker in path:
            path = path[path.index(marker) + 1 :]
            break
    return f"{path}:{code.co_name}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mode", choices=("opcodes", "profile", "cpu"), default="opcodes")
    parser.add_argument("--publishers", type=int, default=4)
    parser.add_argument("--hz", type=float, default=1000.0)
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--depth", type=int, default=10)
    parser.add_argument("--messages", type=int, default=3000)
    parser.add_argument("--warmup", type=int, default=300)
    parser.add_argument("--top", type=int, default=25)
    parser.add_argument("--lines", type=int, default=0, help="also the N busiest source lines")
    args = parser.parse_args()
    lock = lock_domain(DOMAIN)
    os.environ["ROSL_BACKLOG_MS"] = "1000000"
    import rosl
    from rosl.idl.registry import get_message_class

    print(f"rosl from {os.path.dirname(rosl.__file__)}")
    String = get_message_class(TYPE)  # noqa: N806
    rosl.init([], domain_id=DOMAIN)
    node = rosl.Node("sub_opcodes")
    count = [0]
    counter = Counter()
    measured = args.warmup + args.messages

    def on_message(msg: Any) -> None:
        count[0] += 1

    sub = node.create_subscription(String, TOPIC, on_message, args.depth)
    receiver = node.participant._receiver
    polls = [0]  # polls of the transport that found something
    plain_poll = receiver.poll

    def counted_poll(*given: Any) -> int:
        found: int = plain_poll(*given)
        polls[0] += found > 0
        return found

    receiver.poll = counted_poll  # type: ignore[method-assign]
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    children: list[subprocess.Popen[str]] = []
    script = os.path.abspath(__file__)
    try:
        for index in range(args.publishers):
            child = subprocess.Popen(
                [sys.executable, script, "publish", str(index), str(args.hz), str(args.size)],
                stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=bench_env(DOMAIN),
            )  # fmt: skip
            children.append(child)
            assert child.stdout is not None
            if child.stdout.readline().strip() != "ready":
                raise SystemExit("a publisher did not start")
        deadline = time.monotonic() + 60
        while count[0] < args.warmup and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.05)
        if count[0] < args.warmup:
            raise SystemExit(f"only {count[0]} messages arrived in 60 s")
        start, polls[0] = count[0], 0
        if args.mode == "cpu":
            before, taken = os.times(), sub.received + sub.dropped
            while count[0] < measured:
                executor.spin_once(timeout_sec=0.05)
            after = os.times()
            n, taken = count[0] - start, sub.received + sub.dropped - taken
            user, system = after.user - before.user, after.system - before.system
            print(
                f"{n} messages from {args.publishers} publishers: {1e6 * (user + system) / n:.1f}"
                f" us of CPU per message ({1e6 * user / n:.1f} user, {1e6 * system / n:.1f} "
                f"system; {n / max(1, polls[0]):.1f} messages per poll; {taken - n} more read "
                "and dropped from the queue)"
            )
            return
        if args.mode == "profile":
            import cProfile
            import pstats

            profiler = cProfile.Profile()
            profiler.enable()
            while count[0] < measured:
                executor.spin_once(timeout_sec=0.05)
            profiler.disable()
            n = count[0] - start
            print(f"{n} messages; cProfile by own time:")
            pstats.Stats(profiler).sort_stats("tottime").print_stats(args.top)
            return
        counter.start()
        while count[0] < measured:
            executor.spin_once(timeout_sec=0.05)
        counter.stop()
        n = count[0] - start
        total = sum(counter.by_code.values())
        print(
            f"{n} messages from {args.publishers} publishers ({sub.lost} lost on the bus, "
            f"{sub.dropped} dropped from the queue; {n / max(1, polls[0]):.1f} messages per "
            f"poll): {total / n:.1f} opcodes per message"
        )
        for code, ops in counter.by_code.most_common(args.top):
            print(f"  {ops / n:8.1f}  {_where(code)}")
        if args.lines:
            print("by source line:")
            import linecache

            for (code, line), ops in counter.by_line.most_common(args.lines):
                text = linecache.getline(code.co_filename, line or 0).strip()[:60]
                print(f"  {ops / n:8.1f}  {_where(code)}:{line}  {text}")
    finally:
        for child in children:
            if child.stdin is not None:
                child.stdin.close()
        for child in children:
            stop(child)
        rosl.shutdown()
        lock.close()


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "publish":
        publish(int(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]))
    else:
        main()
