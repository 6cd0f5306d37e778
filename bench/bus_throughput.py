"""Throughput, one publisher process -> one subscriber process, rosl vs raw sockets.

Prints, per payload size, delivered messages/s and MB/s for plain Python multicast sockets
(the baseline, measured in the same run) and for rosl's bus (a Writer in this process, a
Reader draining the topic's channel in the subscriber), publisher flat out (saturation), with
the ratio to the baseline and the loss. Then, for 64 B and 1 KB, the same with the writer
coalescing small messages (opt-in: ``create_publisher(..., coalesce=True)`` or
``ROSL_COALESCE=1``). Then the publisher paced at 80 % of the capacity measured above: the
loss there must be 0. Last, the cost of authentication: the bus signed (the default) against
the bus with ``ROSL_KEY=none``, interleaved run by run, as a ratio (aim: >= 0.9).

    python bench/bus_throughput.py [--count N] [--runs R]
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import time
from typing import TYPE_CHECKING

from _harness import BENCH_DOMAIN, finish, raw_receiver, raw_sender, spawn

if TYPE_CHECKING:
    from collections.abc import Iterator

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
    from rosl.bus.multicast import Addressing, MulticastTransport
    from rosl.bus.transport import channel_of

    transport = MulticastTransport(Addressing(BENCH_DOMAIN))
    receiver = transport.receiver()  # the seam's receive loop, as nodes use it
    reader = receiver.reader
    topic = topic_hash("/bench")
    reader.wanted.add(topic)
    receiver.join(channel_of(topic))
    print("ready", flush=True)
    out: list = []
    got = 0
    first = last = 0.0
    idle_since = time.perf_counter()
    while got < count and time.perf_counter() - idle_since < 1.0:
        out.clear()
        receiver.poll(0.2, out)
        if out:
            last = time.perf_counter()
            idle_since = last
            if not got:
                first = last
            got += len(out)
    print(got, last - first, reader.lost() + reader.reassembler.incomplete, flush=True)


def pub_bus(count: int, size: int, coalesce: bool = False, rate: float = 0.0) -> None:
    from rosl.bus.coalesce import DEFAULT_BYTES, Flusher
    from rosl.bus.multicast import Addressing, MulticastTransport
    from rosl.bus.wire import Writer

    transport = MulticastTransport(Addressing(BENCH_DOMAIN))
    writer = Writer(transport, 1, 1, "/bench", "bench/msg/Bytes")
    flusher = Flusher()
    if coalesce:
        writer.coalesce(flusher, DEFAULT_BYTES)
    payload = bytes(size)
    if rate:
        start, clock = time.perf_counter(), time.perf_counter
        for n in range(count):
            due = start + n / rate
            while clock() < due:
                pass
            writer.send(payload)
    else:
        for _ in range(count):
            writer.send(payload)
    flusher.close()


def pub_coalesced(count: int, size: int) -> None:
    pub_bus(count, size, coalesce=True)


@contextlib.contextmanager
def key(value: str | None) -> Iterator[None]:
    """Run the bus (both processes) with ``ROSL_KEY`` set to ``value`` (None: the default)."""
    before = os.environ.get("ROSL_KEY")
    if value is None:
        os.environ.pop("ROSL_KEY", None)
    else:
        os.environ["ROSL_KEY"] = value
    try:
        yield
    finally:
        if before is None:
            os.environ.pop("ROSL_KEY", None)
        else:
            os.environ["ROSL_KEY"] = before


def measure(kind: str, count: int, size: int, rate: float = 0.0) -> tuple[float, float]:
    sub = "raw" if kind == "raw" else "bus"
    child = spawn([__file__, f"sub_{sub}", str(count), str(size)])
    if rate:
        pub_bus(count, size, rate=rate)
    else:
        globals()[f"pub_{kind}"](count, size)
    got, seconds, _lost = finish(child).split()
    got_n, secs = int(got), float(seconds)
    delivered = got_n / secs if secs > 0 else 0.0
    return delivered, 100.0 * (count - got_n) / count


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
    capacity: dict[int, float] = {}
    raw_rates: dict[int, float] = {}
    for size in SIZES:
        count = max(200, min(args.count, int(4e9 / max(size, 1) / 10)))
        raw_rate = 0.0
        if size <= 65000:
            results = [measure("raw", count, size) for _ in range(args.runs)]
            raw_rate = sorted(r for r, _ in results)[len(results) // 2]
            if size == 60000:
                raw60 = raw_rate * size / 1e6
        raw_rates[size] = raw_rate
        results = [measure("bus", count, size) for _ in range(args.runs)]
        bus_rate, loss = sorted(results)[len(results) // 2]
        capacity[size] = bus_rate
        base = raw_rate * size / 1e6 if raw_rate else raw60
        ratio = bus_rate * size / 1e6 / base if base else 0.0
        print(
            f"{size:>8} {raw_rate:>10.0f} {raw_rate * size / 1e6:>9.1f} {bus_rate:>10.0f} "
            f"{bus_rate * size / 1e6:>9.1f} {ratio:>6.2f} {loss:>7.2f}",
            flush=True,
        )
    print("ratio = rosl MB/s / raw MB/s at the same size (1 MiB: / raw 60 KB MB/s)")
    print(f"\n{'coalesced':>9} {'raw msg/s':>10} {'msg/s':>10} {'ratio':>6} {'loss %':>7}")
    for size in (64, 1024):
        count = args.count * 4
        results = [measure("coalesced", count, size) for _ in range(args.runs)]
        rate, loss = sorted(results)[len(results) // 2]
        ratio = rate / raw_rates[size] if raw_rates[size] else 0.0
        print(f"{size:>9} {raw_rates[size]:>10.0f} {rate:>10.0f} {ratio:>6.2f} {loss:>7.2f}")
    print(f"\n{'paced 80%':>9} {'offered/s':>10} {'msg/s':>10} {'loss %':>7}")
    for size in (64, 1024, 60000):
        offered = 0.8 * capacity[size]
        count = max(200, min(args.count, int(offered * 2)))  # about two seconds
        results = [measure("bus", count, size, rate=offered) for _ in range(args.runs)]
        rate, loss = max(results, key=lambda r: r[1])  # the worst run
        print(f"{size:>9} {offered:>10.0f} {rate:>10.0f} {loss:>7.2f}")
    print("paced: the worst of the runs; offered = 80 % of the flat-out rate measured above")
    print(f"\n{'mac cost':>9} {'signed/s':>10} {'unsigned/s':>10} {'ratio':>6}")
    for kind, size in (("bus", 64), ("bus", 1024), ("bus", 60000), ("coalesced", 64)):
        count = max(200, min(args.count, int(4e9 / max(size, 1) / 10)))
        if kind == "coalesced":
            count = args.count * 4  # as above: enough batches to time
        signed, unsigned = [], []
        for _ in range(args.runs):  # interleaved: both see the same machine
            with key(None):
                signed.append(measure(kind, count, size)[0])
            with key("none"):
                unsigned.append(measure(kind, count, size)[0])
        a, b = sorted(signed)[len(signed) // 2], sorted(unsigned)[len(unsigned) // 2]
        label = f"{size}{'c' if kind == 'coalesced' else ''}"
        print(f"{label:>9} {a:>10.0f} {b:>10.0f} {a / b if b else 0.0:>6.2f}")
    print("mac cost: msg/s signed (default key) / with ROSL_KEY=none; c = coalesced")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1].startswith(("sub_", "pub_")):
        globals()[sys.argv[1]](int(sys.argv[2]), int(sys.argv[3]))
    else:
        main()
