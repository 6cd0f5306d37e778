"""rosl over Zenoh against the plain zenoh Python API and against rosl's multicast bus.

Throughput: one publisher process, one subscriber process, the publisher flat out with
pre-serialized std_msgs/msg/UInt8MultiArray payloads of 64 B, 1 KB, 60 KB and 1 MiB; the
subscriber counts what arrives between its first and last message. Latency: ping-pong over
two topics between two processes (median round trip of 64 B). Three contenders, measured in
the same run: plain zenoh (puts with rmw_zenoh's 33-byte attachment, a callback that takes
the payload's bytes into Python, as rosl's raw subscriptions get them), rosl with
``ROSL_TRANSPORT=zenoh`` (publishers, subscriptions, spin), and rosl's multicast bus. All
Zenoh sessions connect to a router this script starts on a free loopback port.

Aims (issue 13): rosl/zenoh >= 0.7x plain zenoh's throughput, <= 1.3x its latency.

    python bench/zenoh.py [--count N] [--rounds N]
"""

from __future__ import annotations

import argparse
import os
import socket
import statistics
import struct
import subprocess
import sys
import time

from _harness import BENCH_DOMAIN, finish, spawn

# this file is named zenoh.py: its folder must not shadow the zenoh package
_HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != _HERE]

SIZES = [64, 1024, 60000, 1048576]
TYPE = "std_msgs/msg/UInt8MultiArray"
KEY = "bench/data"


def _cdr(size: int) -> bytes:
    # UInt8MultiArray: layout (dim: empty sequence, data_offset 0), then the data sequence
    return b"\x00\x01\x00\x00" + struct.pack("<III", 0, 0, size) + bytes(size)


def _config(port: int) -> object:
    import zenoh

    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("connect/endpoints", f'["tcp/127.0.0.1:{port}"]')
    config.insert_json5("listen/endpoints", '["tcp/127.0.0.1:0"]')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("transport/shared_memory/enabled", "false")  # as rosl's and rmw_zenoh's
    return config


def _env(kind: str, port: int) -> None:
    os.environ["ROSL_DOMAIN_ID"] = str(BENCH_DOMAIN)
    os.environ["ROSL_TRANSPORT"] = "zenoh" if kind == "rosl-zenoh" else "multicast"
    os.environ["ZENOH_CONFIG_OVERRIDE"] = (
        f'connect/endpoints=["tcp/127.0.0.1:{port}"];listen/endpoints=["tcp/127.0.0.1:0"]'
    )


# --- children -----------------------------------------------------------------------------------


def sub(kind: str, port: int, count: int) -> None:
    """Count ``count`` messages (or until 3 s of silence); print 'got seconds'."""
    got, first, last = 0, 0.0, 0.0

    def take(data: object) -> None:
        nonlocal got, first, last
        if kind == "zenoh":
            data.payload.to_bytes()  # type: ignore[attr-defined]  # as rosl: the bytes in Python
        last = time.perf_counter()
        if not got:
            first = last
        got += 1

    if kind == "zenoh":
        import zenoh

        session = zenoh.open(_config(port))
        subscriber = session.declare_subscriber(KEY, take)
        print("ready", flush=True)
        while got < count and (not got or time.perf_counter() - last < 3.0):
            time.sleep(0.01)
        del subscriber
    else:
        _env(kind, port)
        import rosl
        from rosl.idl import registry

        rosl.init([])
        node = rosl.create_node("bench_sub")
        msg_type = registry.get_message_class(TYPE)
        node.create_subscription(msg_type, "/bench", take, 1000, raw=True)
        print("ready", flush=True)
        start = time.perf_counter()
        while got < count and time.perf_counter() - (last or start) < 3.0:
            rosl.spin_once(node, timeout_sec=0.05)
    print(got, last - first, flush=True)
    os._exit(0)  # no goodbyes: the measuring side has what it needs


def pong(kind: str, port: int) -> None:
    """Echo pings until 3 s of silence."""
    if kind == "zenoh":
        import zenoh

        session = zenoh.open(_config(port))
        publisher = session.declare_publisher("bench/pong")
        seen = [time.monotonic()]

        def echo(sample: zenoh.Sample) -> None:
            seen[0] = time.monotonic()
            publisher.put(sample.payload.to_bytes(), attachment=bytes(33))

        subscriber = session.declare_subscriber("bench/ping", echo)
        print("ready", flush=True)
        while time.monotonic() - seen[0] < 3.0:
            time.sleep(0.05)
        del subscriber
        return
    _env(kind, port)
    import rosl
    from rosl.idl import registry

    rosl.init([])
    node = rosl.create_node("bench_pong")
    msg_type = registry.get_message_class(TYPE)
    out = node.create_publisher(msg_type, "/pong", 10)
    seen = [time.monotonic()]

    def echo(data: bytes) -> None:
        seen[0] = time.monotonic()
        out.publish(bytes(data))

    node.create_subscription(msg_type, "/ping", echo, 10, raw=True)
    print("ready", flush=True)
    while time.monotonic() - seen[0] < 3.0:
        rosl.spin_once(node, timeout_sec=0.05)


# --- the measuring side ---------------------------------------------------------------------------


def throughput(kind: str, port: int, size: int, count: int) -> float:
    """Messages per second delivered, publisher flat out."""
    child = spawn([__file__, "sub", kind, str(port), str(count)])
    payload = _cdr(size)
    if kind == "zenoh":
        import zenoh

        session = zenoh.open(_config(port))
        publisher = session.declare_publisher(KEY)
        time.sleep(0.5)
        for seq in range(count):
            publisher.put(payload, attachment=struct.pack("<qqB", seq, 0, 16) + bytes(16))
        out = finish(child)
        session.close()
    else:
        _env(kind, port)
        import rosl
        from rosl.idl import registry

        rosl.init([])
        node = rosl.create_node(f"bench_pub_{kind.replace('-', '_')}")
        pub = node.create_publisher(registry.get_message_class(TYPE), "/bench", 1000)
        deadline = time.monotonic() + 10
        while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
            rosl.spin_once(node, timeout_sec=0.05)
        for _ in range(count):
            pub.publish(payload)
        out = finish(child)
        rosl.shutdown()
    got, seconds = out.split()[-2:]
    if int(got) < 2:
        return 0.0  # (nearly) everything dropped: no rate to speak of
    return (int(got) - 1) / max(float(seconds), 1e-9)


def latency(kind: str, port: int, rounds: int) -> float:
    """Median round trip (us) of a 64 B message."""
    child = spawn([__file__, "pong", kind, str(port)])
    payload = _cdr(64)
    times: list[float] = []
    if kind == "zenoh":
        import queue

        import zenoh

        session = zenoh.open(_config(port))
        back: queue.Queue[bytes] = queue.Queue()
        subscriber = session.declare_subscriber("bench/pong", lambda s: back.put(b""))
        publisher = session.declare_publisher("bench/ping")
        time.sleep(0.5)
        for _ in range(rounds):
            start = time.perf_counter()
            publisher.put(payload, attachment=bytes(33))
            back.get(timeout=5)
            times.append(time.perf_counter() - start)
        del subscriber
        session.close()
    else:
        _env(kind, port)
        import rosl
        from rosl.idl import registry

        rosl.init([])
        node = rosl.create_node(f"bench_ping_{kind.replace('-', '_')}")
        msg_type = registry.get_message_class(TYPE)
        got: list[int] = []
        node.create_subscription(msg_type, "/pong", lambda _: got.append(1), 10, raw=True)
        ping = node.create_publisher(msg_type, "/ping", 10)
        deadline = time.monotonic() + 10
        while ping.get_subscription_count() == 0 and time.monotonic() < deadline:
            rosl.spin_once(node, timeout_sec=0.05)
        time.sleep(0.5)
        for _ in range(rounds):
            got.clear()
            start = time.perf_counter()
            ping.publish(payload)
            while not got:
                rosl.spin_once(node, timeout_sec=1.0)
            times.append(time.perf_counter() - start)
        rosl.shutdown()
    child.kill()
    child.wait()
    return statistics.median(times[rounds // 10 :]) * 1e6


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mode", nargs="?", default="main")
    parser.add_argument("rest", nargs="*")
    parser.add_argument("--count", type=int, default=5000)
    parser.add_argument("--rounds", type=int, default=500)
    args = parser.parse_args()
    if args.mode == "sub":
        sub(args.rest[0], int(args.rest[1]), int(args.rest[2]))
        return
    if args.mode == "pong":
        pong(args.rest[0], int(args.rest[1]))
        return
    if args.mode == "one":
        kind, port, size, count = args.rest[0], *map(int, args.rest[1:4])
        value = throughput(kind, port, size, count) if size else latency(kind, port, count)
        print(value, flush=True)
        os._exit(0)
    port = _free_port()
    router = subprocess.Popen(
        [sys.executable, "-m", "rosl", "zenoh", "router", "--listen", f"tcp/127.0.0.1:{port}"],
        stdout=subprocess.PIPE, text=True, env={**os.environ, "ZENOH_CONFIG_OVERRIDE": ""},
    )  # fmt: skip
    assert router.stdout is not None
    router.stdout.readline()
    try:
        _report(port, args.count, args.rounds)
    finally:
        router.terminate()
        router.wait()


def _one(kind: str, port: int, size: int, count: int) -> float:
    """One measurement in its own process (rosl starts and shuts down once per process)."""
    out = subprocess.run(
        [sys.executable, __file__, "one", kind, str(port), str(size), str(count)],
        capture_output=True, text=True, timeout=600, check=True,
    ).stdout  # fmt: skip
    return float(out.split()[-1])


def _ratio(value: float, baseline: float) -> str:
    """``value / baseline`` as ``0.42x``; a dash when the baseline dropped (nearly) all."""
    return f"{value / baseline:>8.2f}x" if baseline > 0 else f"{'-':>9}"


def _report(port: int, count: int, rounds: int) -> None:
    kinds = ["zenoh", "rosl-zenoh", "rosl-multicast"]
    print(
        f"throughput, msgs/s delivered (count {count} per size; publisher flat out;"
        " 0: nearly all dropped)"
    )
    print(f"{'size':>8} " + " ".join(f"{k:>15}" for k in kinds) + "  rosl-zenoh/zenoh")
    for size in SIZES:
        n = count if size < 60000 else max(200, count // 10 if size < 1 << 20 else count // 50)
        rates = [_one(kind, port, size, n) for kind in kinds]
        print(f"{size:>8} " + " ".join(f"{r:>15.0f}" for r in rates)
              + f"  {_ratio(rates[1], rates[0])}")  # fmt: skip
    print(f"round trip, 64 B, median us ({rounds} rounds)")
    lat = [_one(kind, port, 0, rounds) for kind in kinds]
    print("         " + " ".join(f"{v:>15.0f}" for v in lat)
          + f"  {_ratio(lat[1], lat[0])}")  # fmt: skip


if __name__ == "__main__":
    main()
