"""Throughput, one publisher process -> one subscriber process, rosl vs raw sockets.

Prints, per payload size, delivered messages/s and MB/s for plain Python multicast sockets
(the baseline, measured in the same run) and for rosl's bus (a Writer in this process, a
Reader draining the topic's channel in the subscriber, reliable as a subscription's default
QoS is, so a ring's writer waits for it: see ``rosl/bus/shm_ring.py``), publisher flat out
(saturation; a run
sends up to 2.4 GB, so that it measures what a path sustains rather than what its buffers
absorb), with the ratio to the baseline and the loss. Messages above ``ROSL_SHM_THRESHOLD``
(16 KiB), here 60 KB and 1 MiB, take rosl's shared memory. Then, for 64 B and 1 KB, the
same with the writer coalescing small messages (opt-in:
``create_publisher(..., coalesce=True)`` or ``ROSL_COALESCE=1``). Then the publisher paced at
80 % of the capacity measured above (in bursts of half a millisecond of its traffic, sleeping
in between, as a timer-driven node would: a publisher spinning between messages holds a core
the subscriber needs): the loss there must be 0. Last, the cost of authentication: the bus
signed (the default) against the bus with ``ROSL_KEY=none``, interleaved run by run, as a
ratio (aim: >= 0.9).

Then the shared-memory path (``rosl/bus/shm.py``) for 1 MiB messages: rosl flat out (MB/s and
loss), against a plain shared-memory ring + pipe in the same run (the baseline: slots in a
/dev/shm file, indices through one pipe, credits back through another, one copy out per
message, as rosl's reader makes, and a writer that waits for its credits as rosl's waits
for a reliable reader; aim: ratio >= 0.5), the same messages over the wire
(``ROSL_SHM=0``), and rosl paced at 80 % of its flat-out rate (loss must be 0).

    python bench/bus_throughput.py [--count N] [--runs R] [--only-shm]
"""

from __future__ import annotations

import argparse
import contextlib
import mmap
import os
import struct
import sys
import tempfile
import time
from typing import TYPE_CHECKING

from _harness import BENCH_DOMAIN, finish, raw_receiver, raw_sender, spawn

if TYPE_CHECKING:
    from collections.abc import Iterator

SIZES = [64, 1024, 60000, 1048576]
MIB = 1048576
SLOTS = 32  # the baseline ring's slots (rosl's ring of 1 MiB messages has 64)
PACE_S = 0.0005  # a paced publisher sends in bursts of this much of its traffic
# a flat-out run sends up to this many bytes: long enough to measure what a path sustains, not
# what its buffers absorb (the 1024 slots of a ring of 60 KB messages are 61 MB), since the
# paced runs then offer 80 % of it for two seconds
RUN_BYTES = 2_400_000_000

GROUP, PORT = f"239.255.{BENCH_DOMAIN}.9", 17400 + BENCH_DOMAIN + 1  # a port rosl does not use


def flat_count(count: int, size: int) -> int:
    """Messages of a flat-out run of ``size`` bytes (at most ``count``)."""
    return max(200, min(count, int(RUN_BYTES / max(size, 1))))


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
    print(got, last - first, 0, last, flush=True)


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
    reader.held.add(topic)  # a reliable subscription (the default): rings wait for it
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
    print(got, last - first, reader.lost() + reader.reassembler.incomplete, last, flush=True)


def pub_bus(count: int, size: int, coalesce: bool = False, rate: float = 0.0) -> None:
    from rosl.bus.coalesce import DEFAULT_BYTES, Flusher
    from rosl.bus.multicast import Addressing, MulticastTransport
    from rosl.bus.wire import Writer

    transport = MulticastTransport(Addressing(BENCH_DOMAIN))
    writer = Writer(transport, 1, 1, "/bench", "bench/msg/Bytes")
    writer.use_shm(lambda: True)  # large messages through shared memory (unless ROSL_SHM=0)
    flusher = Flusher()
    if coalesce:
        writer.coalesce(flusher, DEFAULT_BYTES)
    payload = bytes(size)
    if rate:
        # messages go in bursts of PACE_S of traffic, each sent when due, and the publisher
        # sleeps until the next burst is due: a publisher that spins between messages holds a
        # core the subscriber of a 2-core machine needs (as a timer-driven node would not)
        burst = max(1, int(rate * PACE_S))
        start, clock = time.perf_counter(), time.perf_counter
        for first in range(0, count, burst):
            ahead = start + first / rate - clock()
            if ahead > 0:
                time.sleep(ahead)
            for _ in range(min(burst, count - first)):
                writer.send(payload)
    else:
        for _ in range(count):
            writer.send(payload)
    flusher.close()
    transport.close()


def pub_coalesced(count: int, size: int) -> None:
    pub_bus(count, size, coalesce=True)


def sub_shmpipe(count: int, size: int, folder: str) -> None:
    """The baseline's reader: an index from the pipe, one copy out of the slot, a credit back."""
    fd = os.open(os.path.join(folder, "ring"), os.O_RDONLY)
    ring = mmap.mmap(fd, SLOTS * size, prot=mmap.PROT_READ)
    os.close(fd)
    print("ready", flush=True)
    indices = os.open(os.path.join(folder, "indices"), os.O_RDONLY)
    credits = os.open(os.path.join(folder, "credits"), os.O_WRONLY)
    view = memoryview(ring)
    got = 0
    first = last = 0.0
    while got < count:
        data = os.read(indices, 4096)
        if not data:
            break
        for (slot,) in struct.iter_unpack("<I", data):
            copy = bytes(view[slot * size : (slot + 1) * size])
            del copy
            os.write(credits, b"c")
            got += 1
        last = time.perf_counter()
        if not first:
            first = last
    print(got, last - first, 0, flush=True)


def shmpipe(count: int, size: int) -> tuple[float, float]:
    """The baseline, both sides: delivered messages/s and loss % (always 0: flow control)."""
    with tempfile.TemporaryDirectory(dir="/dev/shm") as folder:
        fd = os.open(os.path.join(folder, "ring"), os.O_RDWR | os.O_CREAT, 0o600)
        os.posix_fallocate(fd, 0, SLOTS * size)
        ring = mmap.mmap(fd, SLOTS * size)
        os.close(fd)
        os.mkfifo(os.path.join(folder, "indices"), 0o600)
        os.mkfifo(os.path.join(folder, "credits"), 0o600)
        child = spawn([__file__, "sub_shmpipe", str(count), str(size), folder])
        indices = os.open(os.path.join(folder, "indices"), os.O_WRONLY)
        credits = os.open(os.path.join(folder, "credits"), os.O_RDONLY)
        payload, view, free = bytes(size), memoryview(ring), SLOTS
        for n in range(count):
            while not free:
                free += len(os.read(credits, 4096))
            slot = n % SLOTS
            view[slot * size : (slot + 1) * size] = payload
            os.write(indices, struct.pack("<I", slot))
            free -= 1
        got, seconds, _ = finish(child).split()
        os.close(indices)
        os.close(credits)
        view.release()
        ring.close()
    return (int(got) / float(seconds) if float(seconds) > 0 else 0.0), 0.0


@contextlib.contextmanager
def env(name: str, value: str | None) -> Iterator[None]:
    """Run the bus (both processes) with ``name`` set to ``value`` (None: unset)."""
    before = os.environ.get(name)
    if value is None:
        os.environ.pop(name, None)
    else:
        os.environ[name] = value
    try:
        yield
    finally:
        if before is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = before


def key(value: str | None) -> contextlib.AbstractContextManager[None]:
    """Run the bus (both processes) with ``ROSL_KEY`` set to ``value`` (None: the default)."""
    return env("ROSL_KEY", value)


def measure(kind: str, count: int, size: int, rate: float = 0.0) -> tuple[float, float]:
    sub = "raw" if kind == "raw" else "bus"
    child = spawn([__file__, f"sub_{sub}", str(count), str(size)])
    start = time.perf_counter()  # (the same clock in both processes: CLOCK_MONOTONIC)
    if rate:
        pub_bus(count, size, rate=rate)
    else:
        globals()[f"pub_{kind}"](count, size)
    got, seconds, _lost, last = finish(child).split()
    got_n, secs = int(got), float(seconds)
    if secs < 0.001:  # all of it came in one read (coalesced): from the first send on
        secs = float(last) - start
    delivered = got_n / secs if secs > 0 else 0.0
    return delivered, 100.0 * (count - got_n) / count


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--count", type=int, default=40000)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--only-shm", action="store_true", help="60 KB vs raw, then 1 MiB shm")
    args = parser.parse_args()
    if args.only_shm:
        wire_60k(args.runs, args.count)
        shm_section(args.runs)
        return
    print(
        f"{'size':>8} {'raw msg/s':>10} {'raw MB/s':>9} {'bus msg/s':>10} {'bus MB/s':>9} "
        f"{'ratio':>6} {'loss %':>7}"
    )
    raw60 = 0.0
    capacity: dict[int, float] = {}
    raw_rates: dict[int, float] = {}
    for size in SIZES:
        count = flat_count(args.count, size)
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
    print("60 KB and 1 MiB travel through shared memory (ROSL_SHM=0: over the wire); see the end")
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
    shm_section(args.runs)


def median(results: list[tuple[float, float]]) -> tuple[float, float]:
    """The run with the median rate: (rate, its loss %)."""
    return sorted(results)[len(results) // 2]


def wire_60k(runs: int, count: int) -> None:
    """60 KB messages: rosl against raw sockets (flat out), then rosl paced at 80 %."""
    size = 60000
    count = flat_count(count, size)
    raw, bus = [], []
    for _ in range(runs):  # interleaved: both see the same machine
        raw.append(measure("raw", count, size))
        bus.append(measure("bus", count, size))
    (raw_rate, _), (bus_rate, loss) = median(raw), median(bus)
    offered = 0.8 * bus_rate
    paced = [measure("bus", max(200, int(offered * 2)), size, rate=offered) for _ in range(runs)]
    worst = max(loss for _, loss in paced)
    print(f"60 KB: raw {raw_rate * size / 1e6:.1f} MB/s, rosl {bus_rate * size / 1e6:.1f} MB/s "
          f"(loss {loss:.2f} %), ratio {bus_rate / raw_rate if raw_rate else 0.0:.2f} "
          f"(aim >= 0.7); paced at 80 %: loss {worst:.2f} % (worst of {runs})")  # fmt: skip


def shm_section(runs: int) -> None:
    """1 MiB messages through rosl's shared memory, against a plain shm ring + pipe."""
    count = 2000
    print(f"\n{'1 MiB':>22} {'msg/s':>8} {'MB/s':>8} {'loss %':>7}")
    base, rosl = [], []
    for _ in range(runs):  # interleaved: both see the same machine
        base.append(shmpipe(count, MIB))
        rosl.append(measure("bus", count, MIB))
    with env("ROSL_SHM", "0"):
        wire = [measure("bus", 300, MIB) for _ in range(runs)]
    rows = [("shm ring + pipe (base)", base), ("rosl shared memory", rosl)]
    rows.append(("rosl wire (ROSL_SHM=0)", wire))
    for label, results in rows:
        rate, loss = median(results)
        print(f"{label:>22} {rate:>8.0f} {rate * MIB / 1e6:>8.1f} {loss:>7.2f}")
    offered = 0.8 * median(rosl)[0]
    paced = [measure("bus", count, MIB, rate=offered) for _ in range(runs)]
    rate, worst = max(paced, key=lambda r: r[1])
    print(f"{'rosl paced at 80 %':>22} {rate:>8.0f} {rate * MIB / 1e6:>8.1f} {worst:>7.2f}")
    ratio = median(rosl)[0] / median(base)[0] if median(base)[0] else 0.0
    print(f"shm ratio: rosl / shm ring + pipe = {ratio:.2f} (aim >= 0.5); "
          f"wire / shm = {median(wire)[0] / median(rosl)[0] if median(rosl)[0] else 0.0:.2f}; "
          "paced: the worst of the runs (aim: 0 % loss)")  # fmt: skip


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1].startswith(("sub_", "pub_")):
        globals()[sys.argv[1]](int(sys.argv[2]), int(sys.argv[3]), *sys.argv[4:])
    else:
        main()
