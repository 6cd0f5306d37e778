"""Round-trip latency: ping-pong over two topics between two processes, rosl vs raw sockets.

The raw baseline bounces 64 B datagrams between two plain multicast sockets; rosl bounces a
std_msgs/msg/UInt8MultiArray through publishers, subscriptions and spin_once (serialize,
send, receive, decode, callback, on both sides). Prints median and p99 in microseconds and
the ratios, each run measuring raw then rosl back to back, several runs, on a quiet machine
and with a busy loop on the other core. Last, the cost of authentication per hop: rosl signed
(the default) against rosl with ``ROSL_KEY=none``, interleaved (aim: <= 5 us per hop), as
round trips and as the CPU of one send and receive in one process (no scheduling noise).

    python bench/latency.py [--rounds N] [--size BYTES] [--runs R]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

from _harness import BENCH_DOMAIN, finish, raw_receiver, raw_sender, spawn

PORT = 17400 + BENCH_DOMAIN + 2
PING, PONG = f"239.255.{BENCH_DOMAIN}.21", f"239.255.{BENCH_DOMAIN}.22"


def raw_pong() -> None:
    rx = raw_receiver(PING, PORT)
    tx = raw_sender()
    rx.settimeout(5.0)
    print("ready", flush=True)
    buf = bytearray(65536)
    while True:
        try:
            n = rx.recv_into(buf)
        except TimeoutError:
            return
        if n == 1:
            return
        tx.sendto(buf[:n], (PONG, PORT))


def raw_ping(rounds: int, size: int) -> list[float]:
    rx = raw_receiver(PONG, PORT)
    tx = raw_sender()
    rx.settimeout(2.0)
    payload = bytes(size)
    buf = bytearray(65536)
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        tx.sendto(payload, (PING, PORT))
        rx.recv_into(buf)
        times.append(time.perf_counter() - start)
    tx.sendto(b"x", (PING, PORT))
    return times


def rosl_pong() -> None:
    import rosl

    UInt8MultiArray = rosl.get_interface("std_msgs/msg/UInt8MultiArray")  # noqa: N806
    rosl.init([], domain_id=BENCH_DOMAIN)
    node = rosl.Node("pong")
    pub = node.create_publisher(UInt8MultiArray, "/bench_pong", 10)
    node.create_subscription(UInt8MultiArray, "/bench_ping", pub.publish, 10)
    print("ready", flush=True)
    rosl.spin(node)  # until the parent's SIGTERM
    rosl.shutdown()


def rosl_ping(rounds: int, size: int) -> list[float]:
    import rosl

    UInt8MultiArray = rosl.get_interface("std_msgs/msg/UInt8MultiArray")  # noqa: N806
    rosl.init([], domain_id=BENCH_DOMAIN)
    node = rosl.Node("ping")
    pub = node.create_publisher(UInt8MultiArray, "/bench_ping", 10)
    got: list[float] = []
    node.create_subscription(
        UInt8MultiArray, "/bench_pong", lambda m: got.append(time.perf_counter()), 10
    )
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    msg = UInt8MultiArray(data=bytes(max(0, size - 16)))
    deadline = time.monotonic() + 10
    while node.count_subscribers("/bench_ping") == 0 and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    times = []
    for _ in range(rounds + 50):
        got.clear()
        start = time.perf_counter()
        pub.publish(msg)
        limit = start + 1.0
        while not got and time.perf_counter() < limit:
            executor.spin_once(timeout_sec=0.2)
        if got:
            times.append(got[0] - start)
    rosl.shutdown()
    return times[50:]


def stats(times: list[float]) -> tuple[float, float]:
    ordered = sorted(times)
    return statistics.median(ordered) * 1e6, ordered[int(0.99 * (len(ordered) - 1))] * 1e6


def one_run(rounds: int, size: int) -> tuple[tuple[float, float], tuple[float, float]]:
    """(raw, rosl) (median, p99) in microseconds, measured back to back."""
    child = spawn([__file__, "raw_pong"])
    raw = stats(raw_ping(rounds, size))
    finish(child)
    child = spawn([__file__, "rosl_pong"])
    ours = stats(rosl_ping(rounds, size))
    child.terminate()
    finish(child)
    return raw, ours


def measure(runs: int, rounds: int, size: int, label: str) -> None:
    """Interleaved runs; print each run and the median of their figures."""
    rows = []
    for _ in range(runs):
        raw, ours = one_run(rounds, size)
        rows.append((raw, ours))
        print(
            f"  {label:10} raw {raw[0]:7.1f} / {raw[1]:7.1f}   rosl {ours[0]:7.1f} / "
            f"{ours[1]:7.1f}   ratio {ours[0] / raw[0]:5.2f} / {ours[1] / raw[1]:5.2f}",
            flush=True,
        )
    median_ratio = statistics.median(o[0] / r[0] for r, o in rows)
    p99_ratio = statistics.median(o[1] / r[1] for r, o in rows)
    print(
        f"{label}: median of {runs} runs, ratio rosl/raw: median {median_ratio:.2f} "
        f"(target <= 1.5), p99 {p99_ratio:.2f} (target <= 2.0)"
    )


def rosl_only(rounds: int, size: int, key: str | None) -> tuple[float, float]:
    """rosl's (median, p99) with ``ROSL_KEY`` set to ``key`` in both processes (None: default)."""
    before = os.environ.pop("ROSL_KEY", None)
    if key is not None:
        os.environ["ROSL_KEY"] = key
    try:
        child = spawn([__file__, "rosl_pong"])
        ours = stats(rosl_ping(rounds, size))
        child.terminate()
        finish(child)
    finally:
        os.environ.pop("ROSL_KEY", None)
        if before is not None:
            os.environ["ROSL_KEY"] = before
    return ours


def measure_mac(runs: int, rounds: int, size: int) -> None:
    """Signed against unsigned, interleaved; the cost per hop is half the round trip's."""
    costs = []
    for _ in range(runs):
        signed = rosl_only(rounds, size, None)
        unsigned = rosl_only(rounds, size, "none")
        costs.append((signed[0] - unsigned[0]) / 2)
        print(
            f"  mac        signed {signed[0]:7.1f} / {signed[1]:7.1f}   unsigned "
            f"{unsigned[0]:7.1f} / {unsigned[1]:7.1f}   per hop {costs[-1]:+6.1f} us",
            flush=True,
        )
    print(
        f"mac: median of {runs} runs, cost per hop {statistics.median(costs):+.1f} us (target <= 5)"
    )


def mac_cpu(messages: int = 20000, runs: int = 5) -> None:
    """The MAC's CPU per hop, without scheduling noise: one process sends 64 B messages to
    itself over a socket and reads each back, signed against unsigned, interleaved."""
    from rosl.bus import auth
    from rosl.bus.multicast import Addressing, MulticastTransport
    from rosl.bus.wire import Reader, Writer

    key = auth.load(BENCH_DOMAIN)
    costs: dict[bool, list[float]] = {True: [], False: []}
    for _ in range(runs):
        for signed in (True, False):
            used = key if signed else None
            tx = MulticastTransport(Addressing(BENCH_DOMAIN), used)
            rx = MulticastTransport(Addressing(BENCH_DOMAIN), None)
            writer = Writer(tx, 1, 1, "/bench_mac", "bench/msg/Bytes")
            reader = Reader(used)
            reader.want_all = True
            sock = rx.open(writer.channel)
            out: list = []
            start = time.perf_counter()
            for _ in range(messages):
                writer.send(bytes(64))
                reader.drain(sock.recv, out, 1)
            costs[signed].append((time.perf_counter() - start) / messages * 1e6)
            tx.close()
            rx.close()
    signed_us, unsigned_us = statistics.median(costs[True]), statistics.median(costs[False])
    print(
        f"mac cpu: send + receive of one 64 B message {unsigned_us:.2f} us unsigned, "
        f"{signed_us:.2f} us signed: {signed_us - unsigned_us:+.2f} us per hop (target <= 5)"
    )


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--rounds", type=int, default=2000)
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print(f"payload {args.size} B, {args.rounds} round trips per run, two processes")
    print("  (median / p99 in microseconds)")
    measure(args.runs, args.rounds, args.size, "quiet")
    busy = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        measure(args.runs, args.rounds, args.size, "busy core")
    finally:
        busy.kill()
        busy.wait()
    measure_mac(args.runs, args.rounds, args.size)
    mac_cpu()


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] in ("raw_pong", "rosl_pong"):
        globals()[sys.argv[1]]()
    else:
        main()
