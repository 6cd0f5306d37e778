"""Throughput, one publisher process -> one subscriber process, rosl vs raw sockets.

Prints, per payload size, delivered messages/s and MB/s for plain Python multicast sockets
(the baseline, measured in the same run) and for rosl, at the bus level (bytes in, bytes out)
and at the node level (publish a message, callback receives the decoded message), with the
ratio to the baseline and the loss rosl counted. Publisher flat out (saturation).

    python bench/bus_throughput.py [--count N] [--runs R]
"""

from __future__ import annotations

import argparse
import selectors
import sys
import time

from _harness import BENCH_DOMAIN, finish, raw_receiver, raw_sender, spawn

SIZES = [64, 1024, 60000, 1048576]
GROUP, PORT = f"239.255.{BENCH_DOMAIN}.9", 17400 + BENCH_DOMAIN + 1  # a port rosl does not use


def sub_raw(count: int, size: int) -> None:
    sock = raw_receiver(GROUP, PORT)
    sock.settimeout(1.0)
    print("ready", flush=True)
    buf = bytearray(65536)
    got = 0
    first = last = 0.0
    try:
        while got < count:
            n = sock.recv_into(buf)
            last = time.perf_counter()
            if n == 1:
                break  # end marker
            if not got:
                first = last
            got += 1
    except TimeoutError:
        pass
    print(got, last - first, 0, flush=True)


def pub_raw(count: int, size: int) -> None:
    sock = raw_sender()
    payload = bytes(size)
    for _ in range(count):
        sock.sendto(payload, (GROUP, PORT))
    time.sleep(0.2)
    sock.sendto(b"x", (GROUP, PORT))


def sub_bus(count: int, size: int) -> None:
    from rosl.bus.header import topic_hash
    from rosl.bus.multicast import Addressing
    from rosl.bus.transport import MulticastTransport, channel_of
    from rosl.bus.wire import Reader

    transport = MulticastTransport(Addressing(BENCH_DOMAIN))
    reader = Reader()
    topic = topic_hash("/bench")
    reader.wanted.add(topic)
    sock = transport.open(channel_of(topic))
    selector = selectors.DefaultSelector()
    selector.register(sock, selectors.EVENT_READ)
    print("ready", flush=True)
    out: list = []
    got = 0
    first = last = 0.0
    idle_since = time.perf_counter()
    while got < count and time.perf_counter() - idle_since < 1.0:
        if not selector.select(0.2):
            continue
        out.clear()
        reader.drain(sock, out)
        if out:
            last = time.perf_counter()
            idle_since = last
            if not got:
                first = last
            got += len(out)
    print(got, last - first, reader.lost() + reader.reassembler.incomplete, flush=True)


def pub_bus(count: int, size: int) -> None:
    from rosl.bus.multicast import Addressing
    from rosl.bus.transport import MulticastTransport
    from rosl.bus.wire import Writer

    transport = MulticastTransport(Addressing(BENCH_DOMAIN))
    writer = Writer(transport, 1, 1, "/bench", "bench/msg/Bytes")
    payload = bytes(size)
    for _ in range(count):
        writer.send(payload)


def measure(kind: str, count: int, size: int) -> tuple[float, float]:
    child = spawn([__file__, f"sub_{kind}", str(count), str(size)])
    globals()[f"pub_{kind}"](count, size)
    got, seconds, _lost = finish(child).split()
    got_n, secs = int(got), float(seconds)
    rate = got_n / secs if secs > 0 else 0.0
    return rate, 100.0 * (count - got_n) / count


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=40000)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print(
        f"{'size':>8} {'raw msg/s':>10} {'raw MB/s':>9} {'bus msg/s':>10} {'bus MB/s':>9} "
        f"{'ratio':>6} {'loss %':>7}"
    )
    raw60 = 0.0
    for size in SIZES:
        count = max(200, min(args.count, int(4e9 / max(size, 1) / 10)))
        raw_rate = 0.0
        if size <= 65000:
            results = [measure("raw", count, size) for _ in range(args.runs)]
            raw_rate = sorted(r for r, _ in results)[len(results) // 2]
            if size == 60000:
                raw60 = raw_rate * size / 1e6
        results = [measure("bus", count, size) for _ in range(args.runs)]
        bus_rate, loss = sorted(results)[len(results) // 2]
        base = raw_rate * size / 1e6 if raw_rate else raw60
        ratio = bus_rate * size / 1e6 / base if base else 0.0
        print(
            f"{size:>8} {raw_rate:>10.0f} {raw_rate * size / 1e6:>9.1f} {bus_rate:>10.0f} "
            f"{bus_rate * size / 1e6:>9.1f} {ratio:>6.2f} {loss:>7.2f}",
            flush=True,
        )
    print("ratio = rosl MB/s / raw MB/s at the same size (1 MiB: / raw 60 KB MB/s)")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1].startswith(("sub_", "pub_")):
        globals()[sys.argv[1]](int(sys.argv[2]), int(sys.argv[3]))
    else:
        main()
