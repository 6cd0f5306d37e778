"""Foxglove bridge throughput: what one WebSocket client gets, against a rosl subscriber.

    .venv/bin/python bench/bridge.py [--seconds 5] [--runs 3]

Rows:
  /scan      the simulator flat out (`rosl sim turtlebot3_world --real-time-factor 1e9`:
             a 5 Hz x 360-ray LiDAR, so /scan comes as fast as the sim steps)
  1MB image  sensor_msgs/msg/Image of 1 MiB from a rosl publisher sending as fast as it can
For each, against the same producer and one after the other (median of --runs each): a plain
rosl subscription (a node in its own process, messages decoded, depth 100) counts what it gets
in --seconds after its first message; then `rosl bridge foxglove` with one websockets client
subscribed to the topic counts what the client gets. Prints messages/s and MB/s of both (MB/s:
messages/s x the CDR size the client saw) and the ratio bridge / rosl subscriber (1.0: the
bridge forwards all that a subscriber of rosl's own takes).
"""

from __future__ import annotations

import argparse
import json
import re
import select
import signal
import statistics
import struct
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _harness import BENCH_DOMAIN
from _procs import bench_env, rosl_cmd, stop

BOUND = 60.0  # seconds: a start or a first message later than this is a failure
IMAGE_BYTES = 1 << 20

SUBSCRIBER = """
import sys, time, rosl
from rosl.idl.registry import get_message_class
from rosl.node.qos import QoSProfile
topic, type_name, seconds = sys.argv[1], sys.argv[2], float(sys.argv[3])
rosl.init()
node = rosl.Node("bench_counter")
times = []
node.create_subscription(get_message_class(type_name), topic,
                         lambda m: times.append(time.monotonic()), QoSProfile(depth=100))
print("ready", flush=True)
deadline = time.monotonic() + 60
while (not times and time.monotonic() < deadline) or (times and times[-1] - times[0] < seconds):
    rosl.spin_once(node, timeout_sec=0.05)
    if times and time.monotonic() - times[0] > seconds + 5:
        break
inside = [t for t in times if t - times[0] <= seconds] if times else []
print(len(inside), seconds, flush=True)
rosl.shutdown()
"""

IMAGE_PUBLISHER = """
import rosl
from rosl.idl import registry
rosl.init()
node = rosl.Node("bench_camera")
Image = registry.get_message_class("sensor_msgs/msg/Image")
side = 512
image = Image(height=side, width=side, encoding="rgba8", step=side * 4, data=bytes(side * side * 4))
payload = registry.store().serialize(image)
publisher = node.create_publisher(Image, "/bench_image", 10)
print("ready", len(payload), flush=True)
while rosl.ok():
    publisher.publish(payload)
"""


def start(args: list[str], env: dict[str, str]) -> subprocess.Popen[str]:
    return subprocess.Popen(
        args, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True,
    )  # fmt: skip


def read_until(child: subprocess.Popen[str], pattern: str, stream: str = "out") -> re.Match[str]:
    """The first line of ``child``'s stdout/stderr matching ``pattern`` (bounded)."""
    pipe = child.stdout if stream == "out" else child.stderr
    assert pipe is not None
    deadline = time.monotonic() + BOUND
    while time.monotonic() < deadline:
        ready, _, _ = select.select([pipe], [], [], 0.5)
        if ready:
            line = pipe.readline()
            if not line:
                break
            found = re.search(pattern, line)
            if found:
                return found
    stop(child)
    raise RuntimeError(f"{child.args!r} never printed {pattern!r}")


def rosl_subscriber(topic: str, type_name: str, seconds: float, env: dict[str, str]) -> float:
    """Messages/s a plain rosl subscription in its own process takes."""
    child = start([sys.executable, "-c", SUBSCRIBER, topic, type_name, str(seconds)], env)
    try:
        read_until(child, "ready")
        out, _ = child.communicate(timeout=BOUND + seconds)
        count, window = out.split()
        return int(count) / float(window)
    finally:
        stop(child)


def bridge_client(topic: str, seconds: float, env: dict[str, str]) -> tuple[float, int]:
    """Messages/s one websockets client gets through the bridge, and their CDR size."""
    from websockets.sync.client import connect
    from websockets.typing import Subprotocol

    bridge = start([*rosl_cmd(), "bridge", "foxglove", "--port", "0"], env)
    try:
        port = int(read_until(bridge, r"listening on ws://127\.0\.0\.1:(\d+)").group(1))
        url = f"ws://127.0.0.1:{port}"
        with connect(url, subprotocols=[Subprotocol("foxglove.sdk.v1")], max_size=None) as ws:
            ours: set[int] = set()  # our subscription ids (a channel advertised again: a new one)
            count, size, first = 0, 0, 0.0
            deadline = time.monotonic() + BOUND + seconds
            while time.monotonic() < deadline:
                frame = ws.recv(timeout=BOUND)
                if isinstance(frame, str):
                    message = json.loads(frame)
                    for channel in (
                        message.get("channels", []) if message["op"] == "advertise" else []
                    ):
                        if channel["topic"] == topic:  # subscribe, as the Foxglove app does
                            ours.add(len(ours) + 1)
                            subscription = {"id": len(ours), "channelId": channel["id"]}
                            ws.send(
                                json.dumps({"op": "subscribe", "subscriptions": [subscription]})
                            )
                elif frame[0] == 1 and struct.unpack_from("<I", frame, 1)[0] in ours:
                    now = time.monotonic()
                    first = first or now
                    if now - first > seconds:
                        break
                    count, size = count + 1, len(frame) - 13
            if not first:
                raise RuntimeError(f"no message on {topic} through the bridge in {BOUND} s")
        return count / seconds, size
    finally:
        stop(bridge, signal.SIGINT)


def measure(
    topic: str, type_name: str, seconds: float, runs: int, env: dict[str, str]
) -> tuple[float, float, int]:
    """Median messages/s of a rosl subscriber and of a bridge client, and the CDR size."""
    own: list[float] = []
    bridged: list[float] = []
    sizes: list[int] = []
    for _ in range(runs):
        own.append(rosl_subscriber(topic, type_name, seconds, env))
        rate, size = bridge_client(topic, seconds, env)
        bridged.append(rate)
        sizes.append(size)
    return statistics.median(own), statistics.median(bridged), max(sizes)


def main() -> None:
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(143))  # children end by pid
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    env = bench_env(BENCH_DOMAIN)
    env["NO_COLOR"] = "1"
    rows: list[tuple[str, float, float, int]] = []
    sim = start([*rosl_cmd(), "sim", "turtlebot3_world", "--real-time-factor", "1e9",
                 "--headless"], env)  # fmt: skip
    try:
        read_until(sim, "is up", "err")
        found = measure("/scan", "sensor_msgs/msg/LaserScan", args.seconds, args.runs, env)
        rows.append(("/scan (sim flat out)", *found))
    finally:
        stop(sim, signal.SIGINT)
    camera = start([sys.executable, "-c", IMAGE_PUBLISHER], env)
    try:
        read_until(camera, "ready")
        found = measure("/bench_image", "sensor_msgs/msg/Image", args.seconds, args.runs, env)
        rows.append(("1 MiB Image (flat out)", *found))
    finally:
        stop(camera, signal.SIGINT)
    print(f"{'topic':24} {'size':>9} {'rosl msg/s':>11} {'rosl MB/s':>10} {'bridge msg/s':>13} "
          f"{'bridge MB/s':>12} {'ratio':>6}")  # fmt: skip
    for name, own, bridged, size in rows:
        ratio = bridged / own if own else 0.0
        print(f"{name:24} {size:>9} {own:>11.1f} {own * size / 1e6:>10.1f} {bridged:>13.1f} "
              f"{bridged * size / 1e6:>12.1f} {ratio:>6.2f}")  # fmt: skip
    print(
        "ratio = messages/s one Foxglove client gets through the bridge / messages/s a plain "
        "rosl subscription takes, same producer, same run (median of runs)"
    )


if __name__ == "__main__":
    main()
