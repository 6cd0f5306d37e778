"""The cost of one Publisher.publish of a small message, against a raw socket send.

Part 1 counts the Python opcodes one ``publish(msg)`` runs (``sys.settrace`` with opcode
events, after a warm-up), per function, for a few types: std_msgs/msg/String (64 bytes of
CDR, as bench/fanin.py sends), geometry_msgs/msg/PoseStamped (flat: strings and numbers,
nested) and sensor_msgs/msg/LaserScan (arrays: rosbags' generated serializer). The raw
sender's loop body (pack a sequence number into the payload, ``sendto``) is the baseline.

Part 2 times ``publish(msg)`` flat out against that raw loop, both sending 64-byte
datagrams to the topic's multicast group on loopback (TTL 0), interleaved run by run in this
process; it prints calls per second and the ratio rosl / raw (the publisher is signed when
the environment gives a key, as by default; ``ROSL_KEY=none`` measures it unsigned).

    python bench/publish.py [--count N] [--runs R]
"""

from __future__ import annotations

import argparse
import collections
import functools
import os
import statistics
import struct
import sys
import time
from typing import TYPE_CHECKING, Any

from _harness import BENCH_DOMAIN, lock_domain, raw_sender

if TYPE_CHECKING:
    from collections.abc import Callable
    from types import FrameType

DOMAIN = BENCH_DOMAIN + 9
TOPIC = "/bench_publish"
TYPES = ("std_msgs/msg/String", "geometry_msgs/msg/PoseStamped", "sensor_msgs/msg/LaserScan")
RAW_HEAD = struct.Struct("<II")


def opcodes(call: Callable[[], object]) -> collections.Counter[str]:
    """The opcodes one ``call()`` runs, per function (file:name)."""
    counts: collections.Counter[str] = collections.Counter()

    def tracer(frame: FrameType, event: str, arg: object) -> Any:
        frame.f_trace_opcodes = True
        if event == "opcode":
            code = frame.f_code
            counts[f"{os.path.basename(code.co_filename)}:{code.co_name}"] += 1
        return tracer

    sys.settrace(tracer)
    try:
        call()
    finally:
        sys.settrace(None)
    return counts


def message_of(type_name: str) -> Any:
    """A message of ``type_name`` with a few values set (a String of 64 bytes of CDR)."""
    from rosl.idl.registry import get_message_class

    message = get_message_class(type_name)()
    if type_name == "std_msgs/msg/String":
        message.data = "x" * 55  # + 4 (encapsulation) + 4 (length) + 1 (NUL) = 64 B
    elif type_name == "geometry_msgs/msg/PoseStamped":
        message.header.frame_id = "map"
        message.pose.position.x = 1.5
    else:
        message.header.frame_id = "laser"
        message.ranges = [1.0] * 16
    return message


class Raw:
    """The baseline sender: a sequence number packed into a 64-byte payload, then sendto."""

    def __init__(self) -> None:
        from rosl.bus.header import topic_hash
        from rosl.bus.multicast import Addressing
        from rosl.bus.transport import channel_of

        where = Addressing(DOMAIN)
        self.target = (where.group(channel_of(topic_hash(TOPIC))), where.port)
        self.sock = raw_sender()
        self.payload = bytearray(64)
        self.seq = 0
        self.dropped = 0  # a full send buffer (as rosl counts it)

    def send(self) -> None:
        """One message."""
        self.seq += 1
        RAW_HEAD.pack_into(self.payload, 0, 0, self.seq)
        try:
            self.sock.sendto(self.payload, self.target)
        except BlockingIOError:
            self.dropped += 1

    def loop(self, count: int) -> float:
        """Sends per second (the body of :meth:`send`, inlined in the loop)."""
        sock, payload, target, pack_into = self.sock, self.payload, self.target, RAW_HEAD.pack_into
        start = time.perf_counter()
        for seq in range(count):
            pack_into(payload, 0, 0, seq)
            try:
                sock.sendto(payload, target)
            except BlockingIOError:
                self.dropped += 1
        return count / (time.perf_counter() - start)


def publish_loop(publish: Callable[[Any], None], message: Any, count: int) -> float:
    """publish(message) calls per second."""
    start = time.perf_counter()
    for _ in range(count):
        publish(message)
    return count / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--count", type=int, default=50_000, help="calls per timed run")
    parser.add_argument("--runs", type=int, default=5, help="interleaved runs (median)")
    args = parser.parse_args()
    lock = lock_domain(DOMAIN)
    import rosl

    rosl.init([], domain_id=DOMAIN)
    node = rosl.Node("bench_publish")
    signed = node.participant.transport.auth is not None
    print(f"publish cost, domain {DOMAIN}, {'signed' if signed else 'unsigned (ROSL_KEY=none)'}")
    publishers = {t: node.create_publisher(message_of(t).__class__, TOPIC + str(i), 10)
                  for i, t in enumerate(TYPES)}  # fmt: skip
    raw_sender_ = Raw()
    print(f"opcodes per message: raw pack + sendto {sum(opcodes(raw_sender_.send).values())}")
    for type_name, publisher in publishers.items():
        message = message_of(type_name)
        for _ in range(100):  # warm-up: serializers made, caches filled
            publisher.publish(message)
        counts = opcodes(functools.partial(publisher.publish, message))  # no frame of its own
        parts = ", ".join(f"{name} {n}" for name, n in counts.most_common())
        print(f"  publish({type_name}): {sum(counts.values())} ({parts})")
    string_publisher = publishers[TYPES[0]]
    message = message_of(TYPES[0])
    rates: dict[str, list[float]] = {"raw": [], "rosl": []}
    for _ in range(args.runs):
        rates["raw"].append(raw_sender_.loop(args.count))
        rates["rosl"].append(publish_loop(string_publisher.publish, message, args.count))
    raw, ours = statistics.median(rates["raw"]), statistics.median(rates["rosl"])
    print(f"raw sendto loop: {raw:,.0f} /s ({1e6 / raw:.2f} us each)")
    print(f"rosl publish(String 64 B): {ours:,.0f} /s ({1e6 / ours:.2f} us each)")
    print(f"ratio rosl / raw = {ours / raw:.2f}  (median of {args.runs} interleaved runs)")
    raw_sender_.sock.close()
    rosl.shutdown()
    lock.close()


if __name__ == "__main__":
    main()
