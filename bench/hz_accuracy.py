"""`rosl topic hz` accuracy at 1 kHz and 5 kHz, against a raw socket counting the same datagrams.

A publisher process sends std_msgs/msg/String on /bench_hz from a tight loop paced with
time.perf_counter (it counts what it really sent). While it runs, `rosl topic hz /bench_hz
--window N` runs for --seconds and is stopped with SIGINT; its "average rate: X" lines (the
first one dropped as warm-up) give rosl's rate, median over the lines. The baseline is a plain
multicast socket in this process joined to the topic's group/port (channel_of(topic_hash)),
counting the topic's DATA datagrams over the same interval. Per rate, median of --runs runs:

  sent Hz     what the publisher really sent (count / its elapsed time)
  raw Hz      datagrams the raw socket saw per second while hz ran (the baseline)
  rosl Hz     what `rosl topic hz` printed
  err %       (rosl - sent) / sent
  ratio       rosl / raw
  spread %    (max - min) / sent of rosl's per-second lines in a run (how steady they are)
  lost        sequence gaps `rosl topic hz` reported (its "lost:" line), last report

    python bench/hz_accuracy.py [--rates 1000 5000] [--seconds 5] [--runs 3]
"""

from __future__ import annotations

import argparse
import re
import signal
import statistics
import struct
import subprocess
import sys
import threading
import time

from _harness import BENCH_DOMAIN, raw_receiver
from _procs import bench_env, rosl_cmd, stop

DOMAIN = BENCH_DOMAIN + 2
TOPIC = "/bench_hz"
RATE_LINE = re.compile(r"average rate: ([0-9.]+)")
LOST_LINE = re.compile(r"lost: (\d+) message")


def publisher(rate: float, seconds: float) -> None:
    import rosl

    String = rosl.get_interface("std_msgs/msg/String")  # noqa: N806
    rosl.init([], domain_id=DOMAIN)
    node = rosl.Node("hz_publisher")
    pub = node.create_publisher(String, TOPIC, 10)
    msg = String(data="hello world")
    print("ready", flush=True)
    period = 1.0 / rate
    clock = time.perf_counter
    start = clock()
    end = start + seconds
    due = start
    sent = resets = 0
    while True:
        now = clock()
        if now >= end:
            break
        if now < due:
            if due - now > 0.0004:
                time.sleep(due - now - 0.0003)
            continue
        pub.publish(msg)
        sent += 1
        due += period
        if now - due > 0.05:  # fell 50 ms behind (preempted): no burst to catch up
            due = now
            resets += 1
    elapsed = clock() - start
    print(sent, elapsed, resets, flush=True)
    rosl.shutdown()


class RawCounter(threading.Thread):
    """Arrival times of the topic's DATA datagrams, read from a plain multicast socket."""

    def __init__(self) -> None:
        super().__init__(daemon=True)
        from rosl.bus.header import Kind, topic_hash
        from rosl.bus.multicast import Addressing
        from rosl.bus.transport import channel_of

        self.topic = topic_hash(TOPIC)
        self.kind = int(Kind.DATA)
        addressing = Addressing(DOMAIN)
        self.sock = raw_receiver(addressing.group(channel_of(self.topic)), addressing.port)
        self.sock.settimeout(0.2)
        self.stamps: list[float] = []
        self.running = True

    def run(self) -> None:
        buf = bytearray(65536)
        field = struct.Struct("<Q")
        clock = time.perf_counter
        while self.running:
            try:
                n = self.sock.recv_into(buf)
            except TimeoutError:
                continue
            if n >= 28 and buf[3] == self.kind and field.unpack_from(buf, 20)[0] == self.topic:
                self.stamps.append(clock())

    def rate(self, start: float, end: float) -> float:
        inside = [t for t in self.stamps if start <= t <= end]
        if len(inside) < 2:
            return 0.0
        return (len(inside) - 1) / (inside[-1] - inside[0])

    def close(self) -> None:
        self.running = False
        self.join(timeout=2)
        self.sock.close()


def one_run(rate: float, seconds: float, window: int) -> tuple[float, ...]:
    """(sent Hz, raw Hz, rosl Hz, rosl's max - min Hz, lost) for one run."""
    counter = RawCounter()
    counter.start()
    pub = subprocess.Popen(
        [sys.executable, __file__, "publisher", str(rate), str(seconds + 3.0)],
        stdout=subprocess.PIPE,
        text=True,
    )
    hz = None
    try:
        assert pub.stdout is not None
        if pub.stdout.readline().strip() != "ready":
            raise RuntimeError("publisher did not start")
        time.sleep(0.7)  # the publisher is announced and at speed
        hz = subprocess.Popen(
            [*rosl_cmd(), "topic", "hz", TOPIC, "--window", str(window)],
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=bench_env(DOMAIN),
        )
        started = time.perf_counter()
        time.sleep(seconds)
        hz.send_signal(signal.SIGINT)
        try:
            out, _ = hz.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            stop(hz, signal.SIGKILL)
            raise
        stopped = time.perf_counter()
        line = pub.communicate(timeout=seconds + 20)[0].strip().splitlines()[-1]
        sent, elapsed, _resets = line.split()
    finally:
        if hz is not None:
            stop(hz, signal.SIGKILL)
        stop(pub)
        counter.close()
    rates = [float(x) for x in RATE_LINE.findall(out)]
    if not rates:
        raise RuntimeError(f"`rosl topic hz` printed no rate:\n{out}")
    lost = [int(x) for x in LOST_LINE.findall(out)]
    steady = rates[1:] or rates
    raw = counter.rate(started + 1.0, stopped)  # hz needs ~1 s to print its first line
    spread = max(steady) - min(steady)
    ours = statistics.median(steady)
    return int(sent) / float(elapsed), raw, ours, spread, lost[-1] if lost else 0


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--rates", type=float, nargs="+", default=[1000.0, 5000.0])
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--window", type=int, default=0, help="default: one second of messages")
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print(f"`rosl topic hz {TOPIC} --window N` for {args.seconds:g} s; median of {args.runs} runs")
    print(
        f"{'target':>7} {'window':>6} {'sent Hz':>9} {'raw Hz':>9} {'rosl Hz':>9} "
        f"{'err %':>7} {'ratio':>7} {'spread %':>8} {'lost':>6}"
    )
    for rate in args.rates:
        window = args.window or int(rate)
        runs = [one_run(rate, args.seconds, window) for _ in range(args.runs)]
        sent, raw, ours, spread, lost = (statistics.median(c) for c in zip(*runs, strict=True))
        print(
            f"{rate:>7.0f} {window:>6} {sent:>9.1f} {raw:>9.1f} {ours:>9.1f} "
            f"{100 * (ours - sent) / sent:>+7.2f} {ours / raw:>7.4f} {100 * spread / sent:>8.2f} "
            f"{lost:>6.0f}",
            flush=True,
        )
    print("err = (rosl - sent) / sent; ratio = rosl Hz / raw-socket Hz over the same interval")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "publisher":
        publisher(float(sys.argv[2]), float(sys.argv[3]))
    else:
        main()
