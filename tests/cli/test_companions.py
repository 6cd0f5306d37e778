"""``rosl sim ... --serve --bridge`` and ``rosl launch ... --bridge``: the live page and the
Foxglove server run beside the command, and end with it."""

from __future__ import annotations

import json
import socket
import sys
import time
import urllib.request
from typing import TYPE_CHECKING

from tests.bus.helpers import Lines
from tests.conftest import free_port

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes


def page_state(port: int) -> dict[str, object]:
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/state.json", timeout=10) as answer:
        return dict(json.load(answer))


def listening(port: int) -> bool:
    with socket.socket() as probe:
        return probe.connect_ex(("127.0.0.1", port)) == 0


def test_sim_serves_the_page_and_runs_the_bridge_while_it_runs(processes: Processes) -> None:
    page, bridge = free_port(), free_port()
    sim = processes.rosl(
        "sim", "turtlebot3_world", "--headless", "--duration", "600",
        "--serve", "--serve-port", str(page), "--bridge", "--bridge-port", str(bridge),
    )  # fmt: skip
    err = Lines(sim.stderr)
    assert err.wait_line(f"[viz --serve] live view at http://127.0.0.1:{page}/", 60.0), err.lines
    assert err.wait_line("[bridge foxglove]", 60.0), err.lines
    assert listening(bridge)
    deadline = time.monotonic() + 60
    state: dict[str, object] = {}
    while time.monotonic() < deadline:
        state = page_state(page)
        if state.get("scan"):
            break
        time.sleep(0.5)
    assert state.get("scan"), f"the page never showed the sim's scan: {list(state)}"
    out, _ = processes.stop(sim, timeout=20)
    assert sim.returncode == 0
    assert "simulated" in out
    time.sleep(0.5)
    assert not listening(page)  # the companions ended with the sim
    assert not listening(bridge)


def test_a_companion_that_cannot_start_stops_the_command_in_one_line(
    processes: Processes,
) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        sim = processes.rosl(
            "sim", "turtlebot3_world", "--headless", "--duration", "1",
            "--serve", "--serve-port", str(port),
        )  # fmt: skip
        out, err = sim.communicate(timeout=60)
    assert sim.returncode != 0
    assert "Traceback" not in err
    assert "did not start" in err
    assert "simulated" not in out


def test_launch_runs_the_bridge_beside_the_launch(processes: Processes, tmp_path: Path) -> None:
    launch = tmp_path / "one.launch.py"
    launch.write_text(
        "from launch import LaunchDescription\n"
        "from launch.actions import ExecuteProcess\n\n\n"
        "def generate_launch_description():\n"
        f"    return LaunchDescription([ExecuteProcess(cmd=[{sys.executable!r}, '-c',\n"
        "        'import time; time.sleep(600)'])])\n"
    )
    port = free_port()
    child = processes.rosl("launch", str(launch), "--bridge", "--bridge-port", str(port))
    err = Lines(child.stderr)
    assert err.wait_line("[bridge foxglove]", 60.0), err.lines
    deadline = time.monotonic() + 30
    while not listening(port) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert listening(port)
    processes.stop(child, timeout=20)
    time.sleep(0.5)
    assert not listening(port)
    assert child.returncode is not None
    assert child.poll() is not None
