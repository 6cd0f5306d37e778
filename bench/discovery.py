"""Discovery: how long a NEW process needs to see a graph of 20 nodes (no daemon).

Starts 20 node processes, then times, as whole fresh processes and median of several runs:
the interpreter alone (`python -c pass`), `import rosl`, and a process that imports rosl,
queries the graph and prints the node count once the query is complete. Prints the times and
the discovery cost over the interpreter's own start-up.

    python bench/discovery.py [--nodes N] [--runs R]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

from _harness import BENCH_DOMAIN

NODE = """
import rosl, sys
rosl.init([], domain_id={domain})
node = rosl.Node(f"bench_node_{{sys.argv[1]}}")
node.create_publisher(rosl.get_interface("std_msgs/msg/String"), "chatter", 10)
node.create_subscription(rosl.get_interface("std_msgs/msg/String"), "chatter", lambda m: None, 10)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""

QUERY = """
from rosl.node.participant import Participant
p = Participant({domain})
qid = p.discovery.query()
p.discovery.wait_complete(qid, timeout=2.0)
print(len(p.graph.nodes()))
p.close()
"""


def timed(code: str) -> tuple[float, str]:
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=30)
    return time.perf_counter() - start, out.stdout.strip()


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--nodes", type=int, default=20)
    parser.add_argument("--runs", type=int, default=7)
    args = parser.parse_args()
    children = []
    try:
        for index in range(args.nodes):
            child = subprocess.Popen(
                [sys.executable, "-c", NODE.format(domain=BENCH_DOMAIN), str(index)],
                stdout=subprocess.PIPE,
                text=True,
            )
            children.append(child)
        for child in children:
            assert child.stdout is not None
            child.stdout.readline()
        time.sleep(1.5)  # let them settle (announce, idle)
        base = statistics.median(timed("pass")[0] for _ in range(args.runs))
        imp = statistics.median(timed("import rosl")[0] for _ in range(args.runs))
        results = [timed(QUERY.format(domain=BENCH_DOMAIN)) for _ in range(args.runs)]
        seen = [int(out or 0) for _, out in results]
        query = statistics.median(t for t, _ in results)
        print(f"graph: {args.nodes} nodes in {args.nodes} processes; medians of {args.runs} runs")
        print(f"python -c pass               {base * 1000:7.1f} ms")
        print(f"import rosl                  {imp * 1000:7.1f} ms")
        seen_text = f"{min(seen)}..{max(seen)}"
        print(f"new process sees the graph   {query * 1000:7.1f} ms  (nodes seen: {seen_text})")
        print(
            f"discovery over interpreter   {(query - base) * 1000:7.1f} ms  "
            f"(ratio to interpreter start-up {query / base:.1f}x)"
        )
    finally:
        for child in children:
            child.terminate()
        for child in children:
            try:
                child.wait(timeout=5)
            except subprocess.TimeoutExpired:
                os.kill(child.pid, 9)


if __name__ == "__main__":
    main()
