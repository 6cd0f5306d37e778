"""Fan-in: many publisher processes into one subscriber, rosl vs raw sockets, loss in points.

Both halves run in the same run, one after the other, on one domain's groups and port (the
data channel of the topic, as rosl would use it), from 127.0.0.1 with TTL 0:

  raw   --publishers sender processes, each sending a --size byte datagram (its index and a
        sequence number) every 1/--hz s on an absolute schedule (sleeping between sends), to
        one receiver process draining a plain multicast socket (8 MiB SO_RCVBUF asked, as
        rosl asks) in a tight loop;
  rosl  --publishers node processes, each a publisher with a timer at --hz publishing a
        std_msgs/msg/String whose CDR is --size bytes, into one node process with a
        subscription (history depth --depth) whose callback counts.

Every sender says how many it sent; loss = 1 - received / sent (the subscriber's callbacks
for rosl). For rosl it also prints what rosl itself counted and reported: sequence gaps on
the bus (``Subscription.lost``) plus messages pushed out of a full subscription queue
(``Subscription.dropped``), which together must equal the true loss (less a gap at the very
end of a stream: it is counted only when the stream goes on). The last line is the
difference rosl - raw in percentage points (aim: within 1 point).

    python bench/fanin.py [--publishers 20] [--hz 1000] [--size 64] [--seconds 5]
                          [--runs 1] [--depth 10]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import select
import socket
import struct
import subprocess
import sys
import time
from typing import Any

from _harness import BENCH_DOMAIN, lock_domain, raw_receiver, raw_sender
from _procs import bench_env, stop

DOMAIN = BENCH_DOMAIN + 8
TOPIC = "/bench_fanin"
TYPE = "std_msgs/msg/String"
RAW_HEAD = struct.Struct("<II")  # sender index, sequence number
CDR_STRING_OVERHEAD = 9  # encapsulation (4) + length (4) + the string's NUL (1)


def _group_port() -> tuple[str, int]:
    """The group and port rosl uses for the topic's data channel on the bench domain."""
    from rosl.bus.header import topic_hash
    from rosl.bus.multicast import Addressing
    from rosl.bus.transport import channel_of

    where = Addressing(DOMAIN)
    return where.group(channel_of(topic_hash(TOPIC))), where.port


def _wait_go() -> tuple[float, float]:
    """Read ``go <start> <end>`` (wall-clock seconds) from the parent."""
    words = sys.stdin.readline().split()
    return float(words[1]), float(words[2])


def _stdin_says_stop(timeout: float) -> bool:
    ready, _, _ = select.select([sys.stdin], [], [], timeout)
    return bool(ready) and sys.stdin.readline().strip() in ("stop", "")


# --- raw sockets ---------------------------------------------------------------------------------


def raw_recv(publishers: int) -> None:
    group, port = _group_port()
    sock = raw_receiver(group, port)
    sock.setblocking(False)
    granted = sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) // 2
    got = [0] * publishers
    cpu = time.process_time()
    buf = bytearray(65536)
    print("ready", flush=True)
    while True:
        ready, _, _ = select.select([sock, sys.stdin], [], [], 1.0)
        if sock in ready:
            while True:  # a tight drain: nothing between two reads but the count
                try:
                    n = sock.recv_into(buf)
                except BlockingIOError:
                    break
                if n >= RAW_HEAD.size:
                    index = RAW_HEAD.unpack_from(buf)[0]
                    if index < publishers:
                        got[index] += 1
        if sys.stdin in ready:
            sys.stdin.readline()
            break
    print(
        json.dumps({"received": got, "rcvbuf": granted, "cpu": time.process_time() - cpu}),
        flush=True,
    )


def raw_send(index: int, hz: float, size: int) -> None:
    group, port = _group_port()
    sock = raw_sender()
    payload = bytearray(max(size, RAW_HEAD.size))
    print("ready", flush=True)
    start, end = _wait_go()
    cpu = time.process_time()
    period = 1.0 / hz
    sent = 0
    while True:
        due = start + sent * period
        if due >= end:
            break
        delay = due - time.time()
        if delay > 0:
            time.sleep(delay)
        RAW_HEAD.pack_into(payload, 0, index, sent + 1)
        with contextlib.suppress(BlockingIOError):
            sock.sendto(payload, (group, port))
        sent += 1
    print(json.dumps({"sent": sent, "cpu": time.process_time() - cpu}), flush=True)


# --- rosl --------------------------------------------------------------------------------------


def rosl_sub(depth: int) -> None:
    import rosl
    from rosl.idl.registry import get_message_class

    String = get_message_class(TYPE)  # noqa: N806
    rosl.init([], domain_id=DOMAIN)
    node = rosl.Node("fanin_sub")
    count = [0]

    def on_message(msg: Any) -> None:
        count[0] += 1

    sub = node.create_subscription(String, TOPIC, on_message, depth)
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    print("ready", flush=True)
    cpu = time.process_time()
    while not _stdin_says_stop(0.0):
        executor.spin_once(timeout_sec=0.05)
    quiet_since, before = time.monotonic(), count[0]
    while time.monotonic() - quiet_since < 0.5:  # what waits in the socket is not lost
        executor.spin_once(timeout_sec=0.05)
        if count[0] != before:
            quiet_since, before = time.monotonic(), count[0]
    reader = node.participant.reader
    per = [{"received": s.received, "lost": s.lost} for s in reader.streams.values()]
    print(json.dumps({
        "received": count[0], "lost": sub.lost, "dropped": sub.dropped, "streams": per,
        "cpu": time.process_time() - cpu,
    }), flush=True)  # fmt: skip
    rosl.shutdown()


def rosl_pub(index: int, hz: float, size: int) -> None:
    import rosl
    from rosl.idl.registry import get_message_class

    String = get_message_class(TYPE)  # noqa: N806
    rosl.init([], domain_id=DOMAIN)
    node = rosl.Node(f"fanin_pub_{index}")
    pub = node.create_publisher(String, TOPIC, 10)
    msg = String(data="x" * max(0, size - CDR_STRING_OVERHEAD))
    sent = [0]
    print("ready", flush=True)
    start, end = _wait_go()
    cpu = time.process_time()
    time.sleep(max(0.0, start - time.time()))

    def tick() -> None:
        if time.time() < end:
            pub.publish(msg)
            sent[0] += 1

    node.create_timer(1.0 / hz, tick)
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    while time.time() < end:
        executor.spin_once(timeout_sec=max(0.0, end - time.time()))
    print(json.dumps({"sent": sent[0], "cpu": time.process_time() - cpu}), flush=True)
    rosl.shutdown()


# --- this process --------------------------------------------------------------------------------


def _spawn(args: list[str]) -> subprocess.Popen[str]:
    child = subprocess.Popen(
        [sys.executable, __file__, *args], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
        text=True, env=bench_env(DOMAIN),
    )  # fmt: skip
    assert child.stdout is not None
    line = child.stdout.readline().strip()
    if line != "ready":
        stop(child)
        raise SystemExit(f"{args[0]} did not start: {line!r}")
    return child


def _tell(child: subprocess.Popen[str], line: str) -> None:
    assert child.stdin is not None
    child.stdin.write(line + "\n")
    child.stdin.flush()


def _result(child: subprocess.Popen[str], timeout: float = 60.0) -> dict[str, Any]:
    assert child.stdout is not None
    ready, _, _ = select.select([child.stdout], [], [], timeout)
    line = child.stdout.readline() if ready else ""
    stop(child)
    if not line.strip():
        raise SystemExit(f"a child (pid {child.pid}) printed no result")
    result: dict[str, Any] = json.loads(line)
    return result


def run(kind: str, args: argparse.Namespace) -> tuple[int, dict[str, Any]]:
    """One half: (messages sent, the receiver's result)."""
    receiver = _spawn([f"{kind}-recv" if kind == "raw" else "rosl-sub",
                       str(args.publishers if kind == "raw" else args.depth)])  # fmt: skip
    senders: list[subprocess.Popen[str]] = []
    try:
        for index in range(args.publishers):
            role = "raw-send" if kind == "raw" else "rosl-pub"
            senders.append(_spawn([role, str(index), str(args.hz), str(args.size)]))
        time.sleep(1.0)  # discovery settles; every process idle
        start = time.time() + 0.5
        for child in senders:
            _tell(child, f"go {start} {start + args.seconds}")
        results = [_result(child, args.seconds + 60) for child in senders]
        time.sleep(0.5)  # what is in flight arrives (rosl's subscriber then reads until quiet)
        _tell(receiver, "stop")
        got = _result(receiver)
        got["senders_cpu"] = sum(r["cpu"] for r in results)
        return sum(r["sent"] for r in results), got
    finally:
        for child in [*senders, receiver]:
            stop(child)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--publishers", type=int, default=20)
    parser.add_argument("--hz", type=float, default=1000.0, help="messages/s per publisher")
    parser.add_argument("--size", type=int, default=64, help="payload bytes (rosl: the CDR)")
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--runs", type=int, default=1, help="raw/rosl pairs, interleaved")
    parser.add_argument("--depth", type=int, default=10, help="the subscription's history")
    args = parser.parse_args()
    lock = lock_domain(DOMAIN)
    load = os.getloadavg()[0]
    print(
        f"fan-in: {args.publishers} processes x {args.hz:g} Hz x {args.size} B for "
        f"{args.seconds:g} s, domain {DOMAIN}, load {load:.1f} on {os.cpu_count()} cores"
    )
    points = []
    try:
        for run_index in range(args.runs):
            raw_sent, raw = run("raw", args)
            raw_loss = 100.0 * (1 - sum(raw["received"]) / max(1, raw_sent))
            sent, got = run("rosl", args)
            loss = 100.0 * (1 - got["received"] / max(1, sent))
            counted = got["lost"] + got["dropped"]
            true_loss = sent - got["received"]
            print(
                f"run {run_index + 1}: raw   sent {raw_sent}  received {sum(raw['received'])}  "
                f"loss {raw_loss:.2f} %  (SO_RCVBUF granted {raw['rcvbuf'] // 1024} KiB)"
            )
            print(
                f"run {run_index + 1}: rosl  sent {sent}  delivered {got['received']}  "
                f"loss {loss:.2f} %  counted by rosl: {got['lost']} gaps + {got['dropped']} "
                f"queue drops = {counted} of {true_loss} lost; streams {len(got['streams'])}"
            )
            for name, what, n in (("raw", raw, raw_sent), ("rosl", got, sent)):
                print(
                    f"run {run_index + 1}: {name:<5} CPU per message: senders "
                    f"{1e6 * what['senders_cpu'] / max(1, n):.0f} us, receiver "
                    f"{1e6 * what['cpu'] / max(1, n):.0f} us; senders reached "
                    f"{100 * n / (args.publishers * args.hz * args.seconds):.0f} % of their rate"
                )
            points.append(loss - raw_loss)
            print(f"run {run_index + 1}: rosl - raw = {loss - raw_loss:+.2f} points", flush=True)
    finally:
        lock.close()
    if len(points) > 1:
        ordered = sorted(points)
        print(f"median rosl - raw = {ordered[len(ordered) // 2]:+.2f} points")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] in ("raw-recv", "raw-send", "rosl-sub", "rosl-pub"):
        role, rest = sys.argv[1], sys.argv[2:]
        if role == "raw-recv":
            raw_recv(int(rest[0]))
        elif role == "raw-send":
            raw_send(int(rest[0]), float(rest[1]), int(rest[2]))
        elif role == "rosl-sub":
            rosl_sub(int(rest[0]))
        else:
            rosl_pub(int(rest[0]), float(rest[1]), int(rest[2]))
    else:
        main()
