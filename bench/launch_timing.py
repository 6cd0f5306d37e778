"""`rosl launch` of N nodes: time until all are in the graph, and SIGINT until all are gone.

A launch file with N `tutorial_pkg my_publisher` nodes (names bench_<run>_<i>) is generated in
a temporary folder. This process watches the graph with its own rosl participant (event driven:
it wakes on every graph change). Rows, median of --runs runs:

  rosl launch           `rosl launch FILE.launch.py`: from Popen until all N nodes are visible;
                        then SIGINT to the launcher until it has exited and every child pid is
                        gone (every node a fork of the launcher's pre-imported interpreter, the
                        default)
  rosl launch (xml)     the same N nodes from `FILE.launch.xml` (ROS 2's XML format)
  launch, fresh         `rosl launch FILE.launch.py` with ROSL_LAUNCH_ZYGOTE=0: every node a
                        fresh interpreter
  rosl run x N          the baseline: N `python -m rosl run tutorial_pkg my_publisher --ros-args
                        -r __node:=NAME` started in parallel (each execs a second interpreter);
                        stop = SIGINT to each, until all have exited
  entry x N             for reference, the exact command lines the launcher starts
                        (`python -m rosl.pkg.entry ...`, one interpreter each), in parallel

Ratios are row / (rosl run x N), measured in the same run.

    python bench/launch_timing.py [--nodes 10] [--runs 5]
"""

from __future__ import annotations

import argparse
import contextlib
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _harness import BENCH_DOMAIN
from _procs import alive, bench_env, children_of, kill_pids, rosl_cmd, stop, wait_until

DOMAIN = BENCH_DOMAIN + 3
LAUNCH_FILE = """from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    return LaunchDescription(
        [
            Node(package="tutorial_pkg", executable="my_publisher", name=name)
            for name in {names!r}
        ]
    )
"""

XML_LAUNCH_FILE = """<launch>
{nodes}
</launch>
"""
XML_NODE = '  <node pkg="tutorial_pkg" exec="my_publisher" name="{name}"/>'


def write_launch_file(folder: Path, names: list[str], xml: bool) -> Path:
    if xml:
        path = folder / f"{names[0]}.launch.xml"
        nodes = "\n".join(XML_NODE.format(name=name) for name in names)
        path.write_text(XML_LAUNCH_FILE.format(nodes=nodes))
    else:
        path = folder / f"{names[0]}.launch.py"
        path.write_text(LAUNCH_FILE.format(names=names))
    return path


def descendants(pid: int) -> list[int]:
    found, todo = [], [pid]
    while todo:
        for child in children_of(todo.pop()):
            found.append(child)
            todo.append(child)
    return found


class Watcher:
    """This process's view of the graph."""

    def __init__(self) -> None:
        from rosl.node.participant import Participant

        self.participant = Participant(DOMAIN)

    def names(self) -> set[str]:
        return {node.name for node in self.participant.graph.nodes()}

    def wait_all(self, names: set[str], timeout: float = 60.0) -> bool:
        graph = self.participant.graph
        return graph.wait_for(lambda: names <= self.names(), timeout)

    def wait_none(self, names: set[str], timeout: float = 30.0) -> bool:
        graph = self.participant.graph
        return graph.wait_for(lambda: not names & self.names(), timeout)

    def close(self) -> None:
        self.participant.close()


def run_launch(
    watcher: Watcher, folder: Path, names: list[str], xml: bool = False, fresh: bool = False
) -> tuple[float, float]:
    path = write_launch_file(folder, names, xml)
    log = open(folder / "launch.log", "w")  # noqa: SIM115
    pids: list[int] = []
    env = bench_env(DOMAIN)
    if fresh:
        env["ROSL_LAUNCH_ZYGOTE"] = "0"
    start = time.perf_counter()
    launcher = subprocess.Popen(
        [*rosl_cmd(), "launch", str(path)],
        stdout=log,
        stderr=subprocess.STDOUT,
        env=env,
    )
    try:
        if not watcher.wait_all(set(names)):
            raise RuntimeError(f"launch: not all nodes appeared; see {folder / 'launch.log'}")
        up = time.perf_counter() - start
        pids = descendants(launcher.pid)
        start = time.perf_counter()
        launcher.send_signal(signal.SIGINT)
        launcher.wait(timeout=30)
        if wait_until(lambda: not any(alive(p) for p in pids), 30, 0.005) is None:
            raise RuntimeError(f"launch left processes behind: {[p for p in pids if alive(p)]}")
        down = time.perf_counter() - start
        if not watcher.wait_none(set(names)):
            raise RuntimeError("launched nodes still in the graph after they exited")
        return up, down
    finally:
        pids += [p for p in descendants(launcher.pid) if p not in pids]
        stop(launcher, signal.SIGKILL, 5)
        kill_pids(pids)
        log.close()


def run_parallel(
    watcher: Watcher, commands: list[list[str]], names: list[str]
) -> tuple[float, float]:
    children: list[subprocess.Popen[bytes]] = []
    env = bench_env(DOMAIN)
    start = time.perf_counter()
    try:
        for argv in commands:
            children.append(
                subprocess.Popen(
                    argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env
                )
            )
        if not watcher.wait_all(set(names)):
            raise RuntimeError("parallel: not all nodes appeared")
        up = time.perf_counter() - start
        start = time.perf_counter()
        for child in children:
            child.send_signal(signal.SIGINT)
        for child in children:
            child.wait(timeout=30)
        down = time.perf_counter() - start
        if not watcher.wait_none(set(names)):
            raise RuntimeError("nodes still in the graph after they exited")
        return up, down
    finally:
        for child in children:
            stop(child, signal.SIGKILL, 5)


def entry_commands(names: list[str]) -> list[list[str]]:
    from rosl.pkg.executables import command_line, find_executable

    executable = find_executable("tutorial_pkg", "my_publisher")
    return [command_line(executable, ["--ros-args", "-r", f"__node:={n}"]) for n in names]


def run_commands(names: list[str]) -> list[list[str]]:
    return [
        [sys.executable, "-m", "rosl", "run", "tutorial_pkg", "my_publisher", "--ros-args",
         "-r", f"__node:={name}"]
        for name in names
    ]  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--nodes", type=int, default=10)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    kinds = ("rosl launch", "rosl launch (xml)", "launch, fresh", "rosl run x N", "entry x N")
    tags = {"rosl launch": "l", "rosl launch (xml)": "x", "launch, fresh": "f",
            "rosl run x N": "r", "entry x N": "e"}  # fmt: skip
    results: dict[str, list[tuple[float, float]]] = {kind: [] for kind in kinds}
    watcher = Watcher()
    try:
        with tempfile.TemporaryDirectory(prefix="rosl-bench-launch-") as tmp:
            folder = Path(tmp)
            for run in range(args.runs + 1):  # round 0 warms the byte-code cache
                for kind in kinds:
                    names = [f"bench_{tags[kind]}{run}_{i}" for i in range(args.nodes)]
                    time.sleep(0.5)  # let the previous processes finish exiting
                    if kind.startswith("rosl launch"):
                        measured = run_launch(watcher, folder, names, xml=kind.endswith("(xml)"))
                    elif kind == "launch, fresh":
                        measured = run_launch(watcher, folder, names, fresh=True)
                    elif kind == "rosl run x N":
                        measured = run_parallel(watcher, run_commands(names), names)
                    else:
                        measured = run_parallel(watcher, entry_commands(names), names)
                    if run:
                        results[kind].append(measured)
    finally:
        with contextlib.suppress(Exception):
            watcher.close()
    base_up = statistics.median(up for up, _ in results["rosl run x N"])
    base_down = statistics.median(down for _, down in results["rosl run x N"])
    print(f"{args.nodes} nodes (tutorial_pkg my_publisher), median of {args.runs} runs")
    print(f"{'':17} {'all visible s':>13} {'ratio':>6} {'SIGINT->gone s':>15} {'ratio':>6}")
    for kind in kinds:
        up = statistics.median(u for u, _ in results[kind])
        down = statistics.median(d for _, d in results[kind])
        print(f"{kind:17} {up:>13.3f} {up / base_up:>6.2f} {down:>15.3f} {down / base_down:>6.2f}")
    print("ratio = this row / `rosl run x N` (the baseline) in the same run")


if __name__ == "__main__":
    main()
