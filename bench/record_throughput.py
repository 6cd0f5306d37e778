"""`rosl bag record -a` under a flat-out publisher, against the mcap library writing in-process.

Per payload size (100 B, 10 KB, 1 MB of std_msgs/msg/UInt8MultiArray data), median of --runs:

  recorder   `rosl bag record -a -o DIR` in its own process; a publisher process (a rosl node)
             waits until the recorder has subscribed, then sends COUNT messages as fast as it
             can (CDR serialized once, `publish(bytes)`). After a drain pause the recorder gets
             SIGINT; the bag is read back with rosbags' AnyReader. Recorded rate = messages in
             the bag / their log-time span; loss = 1 - recorded / sent.
  baseline   the `mcap` library's Writer, in this process, writing the same CDR payloads to a
             file with the recorder's settings (uncompressed, 4 MiB chunks, finish + fsync).

Prints msgs/s and MB/s of both, the ratio recorded / mcap-writer (MB/s), the publisher's own
send rate, and the loss. The recorder's "Recording stopped: ..., K lost in transit" count is
shown too (what it knew it missed, from sequence gaps).

    python bench/record_throughput.py [--runs 3] [--scale 1.0]
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from _harness import BENCH_DOMAIN
from _procs import bench_env, rosl_cmd, stop

DOMAIN = BENCH_DOMAIN + 4
TOPIC = "/bench_record"
TYPE = "std_msgs/msg/UInt8MultiArray"
SIZES = [(100, 60000), (10_000, 20000), (1_000_000, 300)]  # (payload bytes, messages)
PACED = [(100, 30000, 10_000.0), (1_000_000, 150, 50.0)]  # bytes, messages, msgs/s: 10k/s, 50 MB/s
LOST_LINE = re.compile(r"Recording stopped: (\d+) messages.*?(\d+) lost in transit")


def payload(size: int) -> bytes:
    """CDR (with its encapsulation header) of a UInt8MultiArray with ``size`` data bytes."""
    import numpy as np
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    layout = store.types["std_msgs/msg/MultiArrayLayout"](dim=[], data_offset=0)
    msg = store.types[TYPE](layout=layout, data=np.full(size, 7, dtype=np.uint8))
    return bytes(store.serialize_cdr(msg, TYPE))


def publisher(size: int, count: int, rate: float = 0.0) -> None:
    import rosl

    rosl.init([], domain_id=DOMAIN)
    node = rosl.Node("record_bench_publisher")
    pub = node.create_publisher(rosl.get_interface(TYPE), TOPIC, 10)
    data = payload(size)
    print("ready", flush=True)
    if pub.wait_for_subscribers(1, 15.0) < 1:
        print("no subscriber", flush=True)
        return
    print("subscribed", flush=True)
    if sys.stdin.readline().strip() != "go":
        return
    start = time.perf_counter()
    for n in range(count):
        if rate:  # paced: sleep while more than a millisecond ahead of the schedule
            ahead = start + n / rate - time.perf_counter()
            if ahead > 0.001:
                time.sleep(ahead)
        pub.publish(data)
    print(time.perf_counter() - start, flush=True)
    time.sleep(0.5)  # answer a late type-definition request, if any
    rosl.shutdown()


class Lines(threading.Thread):
    """Collects a child's output lines; ``wait_for`` blocks (bounded) until one matches."""

    def __init__(self, stream) -> None:
        super().__init__(daemon=True)
        self.stream = stream
        self.lines: list[str] = []
        self.changed = threading.Condition()
        self.start()

    def run(self) -> None:
        for line in self.stream:
            with self.changed:
                self.lines.append(line.rstrip("\n"))
                self.changed.notify_all()

    def wait_for(self, text: str, timeout: float) -> bool:
        with self.changed:
            return self.changed.wait_for(lambda: any(text in x for x in self.lines), timeout)

    def text(self) -> str:
        with self.changed:
            return "\n".join(self.lines)


def count_bag(folder: Path) -> tuple[int, int, float]:
    """(messages on TOPIC, their bytes, their log-time span in s), read back with rosbags."""
    from rosbags.highlevel import AnyReader

    n = size = 0
    first = last = 0
    with AnyReader([folder]) as reader:
        wanted = [c for c in reader.connections if c.topic == TOPIC]
        for _, stamp, raw in reader.messages(connections=wanted):
            if not n:
                first = stamp
            last = stamp
            n += 1
            size += len(raw)
    return n, size, (last - first) / 1e9


def record_once(
    size: int, count: int, folder: Path, rate: float = 0.0
) -> tuple[float, float, float, float, int]:
    """(recorded msgs/s, recorded MB/s, publisher msgs/s, loss %, recorder's lost count)."""
    out = folder / "bag"
    env = bench_env(DOMAIN)
    recorder = subprocess.Popen(
        [*rosl_cmd(), "bag", "record", "-a", "-o", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
    )
    log = Lines(recorder.stdout)
    pub = subprocess.Popen(
        [sys.executable, __file__, "publisher", str(size), str(count), str(rate)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert pub.stdin is not None
        assert pub.stdout is not None
        lines = [pub.stdout.readline().strip() for _ in range(2)]
        if lines != ["ready", "subscribed"]:
            raise RuntimeError("publisher did not see the recorder subscribe")
        if not log.wait_for(f"Subscribed to topic '{TOPIC}'", 15.0):
            raise RuntimeError(f"recorder did not subscribe:\n{log.text()}")
        time.sleep(0.3)  # the schema is known: the first messages are not held back
        pub.stdin.write("go\n")
        pub.stdin.flush()
        sent_seconds = float(pub.communicate(timeout=120)[0].strip().splitlines()[-1])
        time.sleep(1.5)  # drain: the recorder reads what its socket still holds
        recorder.send_signal(signal.SIGINT)
        recorder.wait(timeout=60)
        log.join(timeout=5)
    finally:
        stop(pub)
        stop(recorder, signal.SIGKILL, 5)
    if recorder.returncode != 0:
        raise RuntimeError(f"recorder exited {recorder.returncode}:\n{log.text()}")
    got, nbytes, span = count_bag(out)
    match = LOST_LINE.search(log.text())
    told_lost = int(match.group(2)) if match else -1
    rate = (got - 1) / span if got > 1 and span > 0 else 0.0
    mbps = rate * nbytes / got / 1e6 if got else 0.0
    return rate, mbps, count / sent_seconds, 100.0 * (count - got) / count, told_lost


def split_loss(loss: float, told: float, count: int) -> tuple[float, float]:
    """(socket %, recorder %) of a run's loss %, from the recorder's count of lost in transit."""
    socket = 100.0 * told / count if told >= 0 else float("nan")
    return socket, max(0.0, loss - socket)


def mcap_once(size: int, count: int, folder: Path) -> tuple[float, float]:
    """(msgs/s, MB/s) of the mcap library's Writer with the recorder's settings."""
    from mcap.well_known import MessageEncoding, SchemaEncoding
    from mcap.writer import CompressionType, Writer

    data = payload(size)
    path = folder / "baseline.mcap"
    start = time.perf_counter()
    with path.open("wb") as handle:
        writer = Writer(handle, compression=CompressionType.NONE, chunk_size=4 * 1024 * 1024)
        writer.start(profile="ros2", library="bench")
        schema = writer.register_schema(TYPE, SchemaEncoding.ROS2, b"# the type's text")
        channel = writer.register_channel(TOPIC, MessageEncoding.CDR, schema)
        for seq in range(count):
            now = time.time_ns()
            writer.add_message(channel, log_time=now, data=data, publish_time=now, sequence=seq)
        writer.finish()
        handle.flush()
        os.fsync(handle.fileno())
    seconds = time.perf_counter() - start
    path.unlink()
    return count / seconds, count * len(data) / seconds / 1e6


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--scale", type=float, default=1.0, help="multiply message counts")
    args = parser.parse_args()
    print(f"`rosl bag record -a -o DIR` vs mcap Writer in-process; median of {args.runs} runs")
    print(
        f"{'size':>8} {'count':>6} {'pub msg/s':>10} {'rec msg/s':>10} {'rec MB/s':>9} "
        f"{'mcap msg/s':>11} {'mcap MB/s':>10} {'ratio':>6} {'loss %':>7} {'socket %':>8} "
        f"{'recorder %':>10}"
    )
    with tempfile.TemporaryDirectory(prefix="rosl-bench-record-") as tmp:
        folder = Path(tmp)
        for size, base_count in SIZES:
            count = max(10, int(base_count * args.scale))
            recs = []
            for run in range(args.runs):
                run_folder = folder / f"{size}_{run}"
                run_folder.mkdir()
                recs.append(record_once(size, count, run_folder))
                shutil.rmtree(run_folder, ignore_errors=True)
            base = [mcap_once(size, count, folder) for _ in range(args.runs)]
            columns = (statistics.median(c) for c in zip(*recs, strict=True))
            rate, mbps, pub_rate, loss, told = columns
            base_rate, base_mbps = (statistics.median(c) for c in zip(*base, strict=True))
            socket, own = split_loss(loss, told, count)
            print(
                f"{size:>8} {count:>6} {pub_rate:>10.0f} {rate:>10.0f} {mbps:>9.1f} "
                f"{base_rate:>11.0f} {base_mbps:>10.1f} {mbps / base_mbps:>6.3f} {loss:>7.2f} "
                f"{socket:>8.2f} {own:>10.2f}",
                flush=True,
            )
        print(
            f"\npaced: {'size':>8} {'offered/s':>10} {'MB/s':>7} {'loss %':>7} {'socket %':>8} "
            f"{'recorder %':>10}"
        )
        for size, count, rate in PACED:
            losses = []
            for run in range(args.runs):
                run_folder = folder / f"paced_{size}_{run}"
                run_folder.mkdir()
                _, _, _, loss, told = record_once(size, count, run_folder, rate)
                losses.append((loss, told))
                shutil.rmtree(run_folder, ignore_errors=True)
            loss, told = max(losses)
            socket, own = split_loss(loss, told, count)
            print(
                f"        {size:>8} {rate:>10.0f} {rate * size / 1e6:>7.1f} {loss:>7.2f} "
                f"{socket:>8.2f} {own:>10.2f}"
            )
    print("ratio = recorded MB/s / mcap Writer MB/s; loss = 1 - messages in the bag / sent")
    print("socket = what never reached the recorder (its sequence gaps: 'lost in transit');")
    print("recorder = what reached it and is not in the bag (loss - socket)")
    print("paced: the publisher held to the offered rate; the worst of the runs")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "publisher":
        publisher(int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]))
    else:
        main()
