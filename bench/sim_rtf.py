"""Simulator speed: real-time factor headless, and in lock-step with a controller process.

    .venv/bin/python bench/sim_rtf.py [--seconds 60] [--runs 5] [--previous /path/to/older/checkout]

Rows (median of ``--runs``, 5 by default):
  core        physics + scans + odometry bookkeeping, no messages (the ceiling)
  node        the sim node publishing every topic to the bus (as if all were subscribed)
  node-720    the same with a 10 Hz x 720-ray LiDAR
  lock-step   `rosl sim --fast` with the obstacle-avoidance node in another process answering
              every scan over the bus (the demo's set-up, recording off)
Each row prints its real-time factor and its ratio to the core measured in this run. The core
and node rows count this process's CPU seconds (the machine may be shared: wall time would
count other processes' turns on the CPU); lock-step, two processes, counts wall seconds. The
core and node runs take turns (core, node, core, node, ...) and node / core is the median of
each pair's ratio: on a shared machine the speed of both drifts with the others' load, which
would otherwise fall on one row and not the other.
Targets (issue 7): node >= 200x, node-720 >= 100x, lock-step >= 30x; Gazebo runs these
worlds at 1x, ir-sim ~2x with a per-step LiDAR. Issue 17: node >= 0.7 x core, and the core
>= 2 x the previous implementation's on the same machine: ``--previous`` names a checkout of
it (a git worktree, or ``git archive`` of the commit unpacked), whose core runs in a child
process in this run.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _harness import BENCH_DOMAIN

NS = 1_000_000_000


def world(rays: int = 360, rate: float = 5.0):
    from rosl.sim.worldfile import load_world, resolve_world

    loaded = load_world(resolve_world("turtlebot3_world"))
    if rays == 360 and rate == 5.0:
        return loaded
    robots = []
    for spec in loaded.robots:
        lidars = tuple(dataclasses.replace(lidar, samples=rays, rate=rate,
                                           angle_max=lidar.angle_min + 6.28)
                       for lidar in spec.model.lidars)  # fmt: skip
        model = dataclasses.replace(spec.model, lidars=lidars)
        robots.append(dataclasses.replace(spec, model=model))
    return dataclasses.replace(loaded, robots=tuple(robots))


def core(seconds: float, rays: int = 360, rate: float = 5.0) -> float:
    from rosl.sim.simulation import Simulation

    sim = Simulation(world(rays, rate))
    robot = sim.robots[0]
    robot.robot.command(0.1, 0.2)
    end = round(seconds * NS)
    started = time.process_time()
    while sim.now_ns < end:
        sim.step()
        if robot.odom.due(sim.now_ns):
            robot.odom.fire(sim.now_ns)
            sim.sample()
        for lidar, schedule in robot.lidars:
            if schedule.due(sim.now_ns):
                sim.scan(robot, lidar, schedule.fire(sim.now_ns))
    return seconds / (time.process_time() - started)


def node(seconds: float, rays: int = 360, rate: float = 5.0) -> float:
    import rosl
    from rosl.sim.options import SimOptions
    from rosl.sim.sim_node import SimNode
    from rosl.sim.simulation import Simulation

    rosl.init([], domain_id=BENCH_DOMAIN)
    sim_node = rosl.Node("sim")
    try:
        options = SimOptions(real_time_factor=1e9, duration=seconds, headless=True)
        runner = SimNode(Simulation(world(rays, rate)), sim_node, options, publish_all=True)
        started = time.process_time()
        report = runner.run()
        return report.sim_seconds / (time.process_time() - started)
    finally:
        sim_node.destroy_node()
        rosl.try_shutdown()


def lockstep(seconds: float) -> float:
    env = {**os.environ, "ROSL_DOMAIN_ID": str(BENCH_DOMAIN)}
    rosl_cmd = [sys.executable, "-m", "rosl"]
    controller = subprocess.Popen(
        [*rosl_cmd, "run", "my_package", "obstacle_avoidance", "--ros-args",
         "-r", "laser_scan:=/scan", "-p", "use_sim_time:=true", "-p", "distance_threshold:=0.5",
         "-p", "field_of_view:=1.2", "--log-level", "warn"],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        out = subprocess.run(
            [*rosl_cmd, "sim", "turtlebot3_world", "--fast", "--headless",
             "--duration", str(seconds), "--wait-for", "ObstacleAvoidance"],
            env=env, capture_output=True, text=True, timeout=600, check=True,
        ).stdout  # fmt: skip
    finally:
        controller.terminate()
        try:
            controller.wait(timeout=10)
        except subprocess.TimeoutExpired:
            controller.kill()
            controller.wait()
    first = out.splitlines()[0]  # "simulated S s of W in T s (F x real time, lock-step)"
    words = first.split()
    return float(words[1]) / float(words[6])


def median(run, *args: object, repeats: int = 3) -> float:
    return statistics.median(run(*args) for _ in range(repeats))


def paired(seconds: float, runs: int) -> tuple[float, float, float]:
    """Core and node in turns: the medians of each, and the median of each pair's ratio."""
    cores, nodes = [], []
    for _ in range(runs):
        cores.append(core(seconds))
        nodes.append(node(seconds))
    ratio = statistics.median(n / c for c, n in zip(cores, nodes, strict=True))
    return statistics.median(cores), statistics.median(nodes), ratio


def previous_core(tree: Path, seconds: float, runs: int) -> float:
    """The core row of another checkout (its rosl first on the path), in a child process."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    out = subprocess.run(
        [sys.executable, __file__, "--seconds", str(seconds), "--runs", str(runs), "--core-only"],
        env=env, capture_output=True, text=True, timeout=600, check=True,
    ).stdout  # fmt: skip
    return float(out.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--runs", type=int, default=5, help="runs per row (the median counts)")
    parser.add_argument("--previous", type=Path, help="a checkout of the previous implementation")
    parser.add_argument("--core-only", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    seconds, runs = args.seconds, max(1, args.runs)
    if args.core_only:
        print(median(core, seconds, repeats=runs))
        return
    before = previous_core(args.previous.resolve(), seconds, runs) if args.previous else None
    core(min(seconds, 5.0))  # first-use costs (imports, caches) in no row
    node(min(seconds, 5.0))
    base, node_rtf, node_ratio = paired(seconds, runs)
    node_720 = median(node, seconds, 720, 10.0, repeats=runs)
    steps = median(lockstep, seconds, repeats=runs)
    rows = [  # name, real-time factor, ratio to the core, target
        ("core (5 Hz x 360, no messages)", base, 1.0, None),
        ("node (5 Hz x 360, every topic sent)", node_rtf, node_ratio, 200),
        ("node-720 (10 Hz x 720, every topic sent)", node_720, node_720 / base, 100),
        ("lock-step (obstacle avoidance in another process)", steps, steps / base, 30),
    ]
    print(f"{'scenario':52} {'RTF':>8} {'vs core':>8} {'target':>8}")
    for name, rtf, ratio, target in rows:
        aim = f">={target}x" if target else "-"
        print(f"{name:52} {rtf:7.1f}x {ratio:8.2f} {aim:>8}")
    print(f"node / core: {node_ratio:.2f} (target >= 0.7; median of {runs} pairs run in turns); "
          f"core: {base:.1f}x real time")  # fmt: skip
    if before is not None:
        print(f"core of {args.previous}: {before:.1f}x; this core / that: {base / before:.2f} "
              "(target >= 2)")  # fmt: skip


if __name__ == "__main__":
    main()
