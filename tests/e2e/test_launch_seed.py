"""The seeds' launch files, unchanged, under ``rosl launch``: everything starts, talks, and stops.

Real processes on the real bus; every child pid the launcher reports must be gone at the end.
"""

from __future__ import annotations

import os
import signal
from typing import TYPE_CHECKING

import pytest

from tests.conftest import wait_until
from tests.launch.support import ANSI, EXAMPLES, Rosl, assert_all_gone

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from tests.conftest import Processes

SCAN_FEEDER = """
import math
import time

import rosl
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

rosl.init([])
node = rosl.Node("scan_feeder")
scans = node.create_publisher(LaserScan, "/dolly/laser_scan", 10)
received = []
node.create_subscription(Twist, "/dolly/cmd_vel", received.append, 10)


def exchange(ranges, wanted):
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline:
        scans.publish(LaserScan(angle_min=-1.0, angle_max=1.0, range_max=10.0, ranges=ranges))
        rosl.spin_once(node, timeout_sec=0.1)
        for msg in received:
            if wanted(msg):
                return msg
    return None


for label, ranges, wanted in (
    ("near", [2.0, 0.5, math.nan, 3.0], lambda m: m.angular.z != 0.0),
    ("far", [2.0, 1.5, math.nan, 3.0], lambda m: m.linear.x != 0.0),
):
    received.clear()
    msg = exchange(ranges, wanted)
    if msg is None:
        print(label, "nothing", flush=True)
    else:
        print(f"{label} linear.x={msg.linear.x:.2f} angular.z={msg.angular.z:.2f}", flush=True)
rosl.shutdown()
"""


@pytest.fixture
def rosl(processes: Processes, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Rosl]:
    """rosl commands as processes, with the examples on the path and a temporary log folder."""
    monkeypatch.setenv("ROSL_LOG_DIR", str(tmp_path / "log"))
    monkeypatch.setenv("ROSL_PACKAGE_PATH", str(EXAMPLES))
    monkeypatch.delenv("NO_COLOR", raising=False)
    runner = Rosl(processes)
    try:
        yield runner
    finally:
        runner.close()


def rosl_lines(rosl: Rosl, *args: str) -> list[str]:
    """The stdout lines of a short rosl command (empty when it fails)."""
    code, out, _ = rosl.run(*args)
    return out.splitlines() if code == 0 else []


def test_the_first_seeds_launch_file_starts_three_nodes_that_talk_and_one_ctrl_c_stops_them(
    rosl: Rosl,
) -> None:
    launch = rosl.start("launch", "tutorial_pkg", "my_launch.py")

    assert launch.wait_for(r"process started with pid", count=3), launch.both()
    assert list(launch.started()) == ["my_publisher-1", "my_subscriber-2", "timer_node-3"]
    pids = launch.pids()
    assert launch.wait_for(
        r"^\[my_subscriber-2\] \[INFO\] \[\d+\.\d+\] \[subscriber_node\]: I heard: counter=1 "
    ), launch.both()
    assert launch.wait_for(r"^\[my_publisher-1\] \[INFO\] .*\[publisher_node\]: Publishing: ")

    # the launch file's parameters=[{"timer_period_s": 1.5}] reached the node
    assert wait_until(
        lambda: (
            rosl_lines(rosl, "param", "get", "/timer_node", "timer_period_s")
            == ["Double value is: 1.5"]
        ),
        timeout=60.0,
    ), rosl.run("param", "get", "/timer_node", "timer_period_s")
    assert launch.wait_for(r"^\[timer_node-3\] .*\[timer_node\]: Timer period: 1\.5 s$")
    expected = ["/publisher_node", "/subscriber_node", "/timer_node"]
    assert wait_until(lambda: rosl_lines(rosl, "node", "list") == expected, timeout=60.0), (
        rosl_lines(rosl, "node", "list")
    )

    os.killpg(launch.pid, signal.SIGINT)  # Ctrl-C in a terminal reaches the launcher's group

    assert launch.finish(timeout=30.0) == 0, launch.both()
    for label, [pid] in launch.started().items():
        assert f"[INFO] [{label}]: process has finished cleanly [pid {pid}]" in launch.lines(), (
            launch.both()
        )
    assert not ANSI.search(launch.text("out")), "escape codes in piped output"
    assert "Traceback" not in launch.text("out") + launch.text("err")
    assert_all_gone(pids)


def test_the_second_seeds_launch_file_remaps_the_obstacle_avoidance_node_to_dolly(
    rosl: Rosl, processes: Processes
) -> None:
    launch = rosl.start("launch", "my_package", "obstacle_avoidance.launch.py")
    assert launch.wait_for(r"process started with pid"), launch.both()
    pids = launch.pids()

    def info() -> list[str]:
        return rosl_lines(rosl, "node", "info", "/ObstacleAvoidance")

    assert wait_until(lambda: "    /dolly/laser_scan: sensor_msgs/msg/LaserScan" in info(), 60.0), (
        f"{info()}\n{launch.both()}"
    )
    lines = info()
    subscribers = lines[lines.index("  Subscribers:") + 1 : lines.index("  Publishers:")]
    publishers = lines[lines.index("  Publishers:") + 1 : lines.index("  Service Servers:")]
    assert subscribers == ["    /dolly/laser_scan: sensor_msgs/msg/LaserScan"]
    assert "    /dolly/cmd_vel: geometry_msgs/msg/Twist" in publishers
    assert not any(line.startswith("    /cmd_vel:") for line in publishers)

    feeder = processes.python(SCAN_FEEDER)
    out, err = feeder.communicate(timeout=90.0)
    assert feeder.returncode == 0, err
    assert out.splitlines() == [
        "near linear.x=0.00 angular.z=0.30",
        "far linear.x=0.30 angular.z=0.00",
    ], err
    assert launch.wait_for(
        r"^\[obstacle_avoidance-1\] .*\[ObstacleAvoidance\]: Distance is: '0\.500000'"
    ), launch.both()

    assert launch.interrupt() == 0, launch.both()
    assert_all_gone(pids)
