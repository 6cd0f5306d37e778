"""Floods against a node process: strangers, fragments, random senders, replays, forged jumps.

A talker (100 Hz) and a victim listener run on the test's domain; this process floods the
domain's groups from 127.0.0.1 with TTL 0 for about 3 s per mode, in 10 ms batches. After each
flood: both processes are alive, the victim's RSS (VmRSS, and VmHWM reset before the flood, of
its pid) grew by less than 64 MiB, the talker's messages still arrive, nothing was delivered
to the victim's callback twice and nothing forged was delivered; at the end the loss the bus
counted is no more than the real gaps the callback saw, and nobody printed a traceback.

Datagrams signed with the test user's key stand for a fuzzer holding the key: such a process
may publish (its messages, ``keyed N``, are delivered by design, and counted apart); another
key or no MAC stands for another user. Only counts and memory are asserted, never a rate.
"""

from __future__ import annotations

import random
import select
import socket
import struct
import threading
import time
from typing import TYPE_CHECKING

import pytest

from rosl.bus import auth
from rosl.bus.header import HEADER, MAGIC, VERSION, Flags, Kind, topic_hash, type_hash, unpack
from rosl.bus.multicast import Addressing, open_receiver
from rosl.bus.transport import channel_of
from rosl.graph.announce import DISCOVERY_TOPIC, DISCOVERY_TYPE
from tests.bus.helpers import TALKER, Lines, wait_exit

if TYPE_CHECKING:
    import subprocess
    from collections.abc import Callable

    from tests.conftest import Processes

TOPIC = "/flood_chatter"
TOPIC_HASH = topic_hash(TOPIC)
TYPE_HASH = type_hash("std_msgs/msg/String")
CHANNEL = channel_of(TOPIC_HASH)
DISCOVERY = (topic_hash(DISCOVERY_TOPIC), type_hash(DISCOVERY_TYPE))
PREFIX = "hello "  # what TALKER publishes
MIB = 1024 * 1024
RSS_ALLOWANCE = 64 * MIB
# the bounds wire.py documents (literals: a test must not follow a changed constant)
MAX_STREAMS = 8192
MAX_RETIRED = 16384
FLOOD_SECONDS = 3.0
# (claimed total, fragment size) of the fragment flood, in turn: 200 KB messages are buffered
# whole at once, 8 MB ones are mapped lazily and charged as they fill
FRAGMENTS = [(8_000_000, 60_000), (200_000, 60_000), (8_000_000, 123), (200_000, 1000)]
TINY = 123  # the smallest fragment of an 8 MB message (the count field has 16 bits)

VICTIM = r"""
import sys
import time
import rosl
from std_msgs.msg import String

rosl.init()
node = rosl.Node(sys.argv[1])
reader = node.participant.reader
talker_seen = bytearray(1 << 17)  # talker sequence numbers delivered, a bit each
keyed_seen = bytearray(1 << 20)  # "keyed N" numbers delivered, a bit each
c = {"good": 0, "keyed": 0, "forged": 0, "dup": 0, "kdup": 0}
talker = None
first = last = 0

def mark(bits, number):
    while number >> 3 >= len(bits):
        bits.extend(bytes(len(bits)))
    byte, bit = number >> 3, 1 << (number & 7)
    was = bits[byte] & bit
    bits[byte] |= bit
    return bool(was)

def on_message(msg, info):
    global talker, first, last
    data, gid = msg.data, info["publisher_gid"]
    seq = info["publication_sequence_number"]
    if data.startswith("hello "):
        if talker is None:
            talker, first = gid, seq
        if gid != talker:
            c["forged"] += 1
        elif mark(talker_seen, seq):
            c["dup"] += 1
        else:
            c["good"] += 1
            last = max(last, seq)
    elif data.startswith("keyed ") and data[6:].isdigit():
        c["kdup" if mark(keyed_seen, int(data[6:])) else "keyed"] += 1
    else:
        c["forged"] += 1

# deep enough that one poll's deliveries never overflow it: every message reaches the callback
sub = node.create_subscription(String, sys.argv[2], on_message, 5000)

def report():
    rs = reader.reassembler
    fields = {
        "t": round(time.monotonic(), 3), **c,
        "gaps": last - first + 1 - c["good"] if c["good"] else 0,
        "lost": reader.lost(sub._topic_hash), "streams": len(reader.streams),
        "retired": len(reader._retired), "held": rs.held, "budget": rs.budget,
        "qdropped": sub.dropped,
        **{"drop_" + k: v for k, v in reader.dropped().items()},
    }
    print("stat", " ".join(f"{k}={v}" for k, v in fields.items()), flush=True)

node.create_timer(0.2, report)
print("up", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


# --- datagrams ---------------------------------------------------------------------------------


class Forge:
    """Datagrams as the wire builds them: signed with the key, another key, a bad MAC, or none."""

    def __init__(self, domain: int, seed: int) -> None:
        key = auth.load(domain)
        assert key is not None, "the tests run with the default per-user key"
        self.key = key
        self.other = auth.Auth(b"another user's key", domain, "test")
        self.rng = random.Random(seed)
        self.pool = self.rng.randbytes(60_000)
        self.keyed = 0  # "keyed N" numbers used
        self.sent_keyed: list[bytes] = []  # the last key-holder datagrams (to replay)

    def datagram(
        self,
        payload: bytes,
        sender: int,
        seq: int,
        *,
        sign: str = "key",
        kind: int = Kind.DATA,
        endpoint: int = 1,
        count: int = 1,
        total: int | None = None,
        topic: tuple[int, int] = (TOPIC_HASH, TYPE_HASH),
        stamp: int | None = None,
    ) -> bytes:
        flags = 0 if sign == "none" else int(Flags.SIGNED)
        head = HEADER.pack(
            MAGIC, VERSION, kind, flags, count, sender, seq & 0xFFFFFFFF, topic[0], topic[1],
            0, endpoint, len(payload) if total is None else total,
            time.time_ns() if stamp is None else stamp,
        )  # fmt: skip
        body = head + payload
        mac = {"key": self.key.mac, "other": self.other.mac}.get(sign)
        if mac is not None:
            return body + mac(body)
        return body + (self.rng.randbytes(16) if sign == "bad" else b"")

    def keyed_message(
        self, sender: int, seq: int, endpoint: int = 1, stamp: int | None = None
    ) -> bytes:
        """A message a key holder publishes: delivered by design, numbered for the victim."""
        self.keyed += 1
        text = cdr_string(f"keyed {self.keyed}")
        datagram = self.datagram(text, sender, seq, endpoint=endpoint, stamp=stamp)
        self.sent_keyed = [*self.sent_keyed[-499:], datagram]
        return datagram

    def strangers(self, n: int) -> tuple[int, bytes]:
        """Another user's traffic: other key, no MAC, or a wrong one; data and discovery."""
        sender, seq = self.rng.getrandbits(64), self.rng.getrandbits(32)
        sign = ("other", "none", "bad")[n % 3]
        if n % 5 == 4:
            hello = (
                f'{{"op":"hello","process":{{"sender":"{sender:016x}","pid":{n},'
                '"nodes":[{"name":"ghost","namespace":"/"}]}}'
            )
            return 0, self.datagram(hello.encode(), sender, seq, sign=sign, kind=Kind.DISCOVERY,
                                    topic=DISCOVERY)  # fmt: skip
        if n % 5 == 3:  # fragment 0 of an 8 MB message
            datagram = self.datagram(self.pool[:1000], sender, seq, sign=sign, count=8000,
                                     total=8_000_000)  # fmt: skip
            return CHANNEL, datagram
        return CHANNEL, self.datagram(cdr_string(f"stranger {n}"), sender, seq, sign=sign)

    def fragments(self, n: int) -> tuple[int, bytes]:
        """Key holder: fragment 0 of messages that never complete (200 KB and 8 MB claimed)."""
        total, size = FRAGMENTS[n % len(FRAGMENTS)]
        sender = self.rng.getrandbits(64)
        return CHANNEL, self.datagram(self.pool[:size], sender, 1, count=-(-total // size),
                                      total=total)  # fmt: skip

    def tiny_fragments(self, n: int) -> tuple[int, bytes]:
        """Key holder: fragment 0 of 8 MB messages in the smallest fragments they can have."""
        sender = self.rng.getrandbits(64)
        return CHANNEL, self.datagram(self.pool[:TINY], sender, 1, count=-(-8_000_000 // TINY),
                                      total=8_000_000)  # fmt: skip

    def senders(self, n: int) -> tuple[int, bytes]:
        """Key holder: one message from each of many made-up sender ids."""
        rng = self.rng
        sender, seq, endpoint = rng.getrandbits(64), rng.getrandbits(32), rng.randrange(1, 9)
        return CHANNEL, self.keyed_message(sender, seq, endpoint)


def cdr_string(text: str) -> bytes:
    """A std_msgs/msg/String in CDR (little endian, with its encapsulation header)."""
    raw = text.encode() + b"\x00"
    return b"\x00\x01\x00\x00" + struct.pack("<I", len(raw)) + raw


def far_ahead(n: int) -> int:
    """The n-th forged sequence number: far ahead of the talker's and of each other's.

    2**31 + multiples of 65537 (prime) modulo 2**31 - 2**20: never within a loss window of
    one another, nor of the talker's small numbers, nor just behind them (2**32 - x).
    """
    return (1 << 31) + n * 65537 % ((1 << 31) - (1 << 20))


def flood(domain: int, make: Callable[[int], tuple[int, bytes]], rate: float) -> int:
    """Send ``make(n)`` for FLOOD_SECONDS at about ``rate``/s; return how many went out."""
    addressing = Addressing(domain)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
    batch = max(1, int(rate / 100))
    start = time.monotonic()
    sent = n = 0
    try:
        while time.monotonic() - start < FLOOD_SECONDS:
            wait = start + n / rate - time.monotonic()
            if wait > 0:
                time.sleep(min(wait, 0.01))
                continue
            for _ in range(batch):
                channel, datagram = make(n)
                n += 1
                try:
                    sock.sendto(datagram, (addressing.group(channel), addressing.port))
                    sent += 1
                except OSError:
                    pass  # a full send buffer: the count is what the test needs
    finally:
        sock.close()
    return sent


# --- the two processes ----------------------------------------------------------------------------


def memory(pid: int) -> dict[str, int]:
    """VmRSS and VmHWM of ``pid`` in bytes."""
    with open(f"/proc/{pid}/status") as f:
        return {x[:5]: int(x.split()[1]) * 1024 for x in f if x.startswith(("VmRSS", "VmHWM"))}


class Peak:
    """The peak RSS of a pid from now on: VmHWM reset, plus samples every 20 ms."""

    def __init__(self, pid: int) -> None:
        self.pid = pid
        with open(f"/proc/{pid}/clear_refs", "w") as f:
            f.write("5")  # VmHWM := VmRSS (our own child)
        self.start = memory(pid)["VmRSS"]
        self.peak = self.start
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.02):
            try:
                self.peak = max(self.peak, memory(self.pid)["VmRSS"])
            except (OSError, KeyError):
                return  # gone: the liveness assertion says so

    def growth(self) -> int:
        self._stop.set()
        self._thread.join(5.0)
        self.peak = max(self.peak, *memory(self.pid).values())
        return self.peak - self.start


class Scenario:
    """A talker and a victim listener on the test's domain, and what the victim reports."""

    def __init__(self, processes: Processes, domain: int, seed: int) -> None:
        self.domain = domain
        self.forge = Forge(domain, seed)
        self.victim: subprocess.Popen[str] = processes.python(VICTIM, "flood_victim", TOPIC)
        self.talker: subprocess.Popen[str] = processes.python(TALKER, "flood_talker", TOPIC)
        self.out, self.err = Lines(self.victim.stdout), Lines(self.victim.stderr)
        self.talker_out, self.talker_err = Lines(self.talker.stdout), Lines(self.talker.stderr)
        assert self.out.wait_line("up", 30.0), f"victim: {self.err.rest(1.0)}"
        assert self.talker_out.wait_line("up", 30.0), f"talker: {self.talker_err.rest(1.0)}"
        self.wait_good(20, "before any flood")

    def stat(self) -> dict[str, float]:
        line = next((x for x in reversed(self.out.lines) if x.startswith("stat ")), "stat t=0")
        return {k: float(v) for k, v in (x.split("=", 1) for x in line.split()[1:])}

    def stat_after(self, moment: float) -> dict[str, float]:
        """The first stat line the victim printed after ``moment`` (time.monotonic)."""
        assert self.out.wait_for(lambda _: self.stat()["t"] > moment, 30.0), (
            f"the victim stopped reporting: {self.err.rest(1.0)[-20:]}"
        )
        return self.stat()

    def wait_good(self, count: int, when: str) -> None:
        assert self.out.wait_for(lambda _: self.stat().get("good", 0) >= count, 30.0), (
            f"the victim got {self.stat().get('good')} of the talker's messages {when}, "
            f"wanted {count}: {self.err.rest(1.0)[-20:]}"
        )

    def flood(self, make: Callable[[int], tuple[int, bytes]], rate: float) -> dict[str, float]:
        """Flood, then check the guarantees; return the victim's counts afterwards."""
        peak = Peak(self.victim.pid)
        sent = flood(self.domain, make, rate)
        assert sent > 0
        assert self.victim.poll() is None, f"the victim died: {self.err.rest(1.0)[-30:]}"
        assert self.talker.poll() is None, f"the talker died: {self.talker_err.rest(1.0)[-30:]}"
        after = self.stat_after(time.monotonic())
        self.wait_good(int(after["good"]) + 30, "after the flood")
        growth = peak.growth()
        assert growth < RSS_ALLOWANCE, (
            f"the victim's RSS grew by {growth / MIB:.1f} MiB (from {peak.start / MIB:.1f}) "
            f"under the flood; reassembly budget {self.stat()['budget'] / MIB:.0f} MiB"
        )
        return self.check_delivered()

    def check_delivered(self) -> dict[str, float]:
        stat = self.stat_after(time.monotonic())
        assert stat["dup"] == 0, f"talker messages delivered twice: {stat}"
        assert stat["kdup"] == 0, f"key-holder messages delivered twice: {stat}"
        assert stat["forged"] == 0, f"forged messages delivered: {stat}"
        return stat

    def capture(self, want: int = 100) -> list[bytes]:
        """The talker's real datagrams, read from the wire (bounded wait)."""
        sock = open_receiver(Addressing(self.domain), CHANNEL)
        got: list[bytes] = []
        deadline = time.monotonic() + 20.0
        try:
            while time.monotonic() < deadline and len(got) < want:
                ready, _, _ = select.select([sock], [], [], 0.1)
                while ready:
                    try:
                        datagram = sock.recv(65536)
                    except BlockingIOError:
                        break
                    head = unpack(datagram)
                    if head is not None and head.topic == TOPIC_HASH and b"hello " in datagram:
                        got.append(datagram)
        finally:
            sock.close()
        assert len(got) >= want // 2, f"captured {len(got)} of the talker's datagrams"
        return got

    def finish(self) -> dict[str, float]:
        """Stop the talker, then check the loss count and both processes' stderr."""
        self.talker.send_signal(2)
        assert wait_exit(self.talker, 15.0) is not None, "the talker did not stop"
        # once the talker's goodbye is handled its stream is retired: the count is final
        stat = self.stat_after(time.monotonic() + 1.0)
        assert stat["lost"] <= stat["gaps"], (
            f"the bus counted {stat['lost']:.0f} lost messages but the callback saw only "
            f"{stat['gaps']:.0f} gaps in the talker's numbers: {stat}"
        )
        self.victim.send_signal(2)
        wait_exit(self.victim, 15.0)
        for name, err in (("victim", self.err), ("talker", self.talker_err)):
            text = "\n".join(err.rest(3.0))
            assert "Traceback" not in text, f"the {name} raised:\n{text[-3000:]}"
            assert "Exception in thread" not in text, f"the {name} lost a thread:\n{text[-3000:]}"
        return stat


# --- the floods ----------------------------------------------------------------------------------


def test_strangers_flood_reaches_no_callback(processes: Processes, domain_id: int) -> None:
    bus = Scenario(processes, domain_id, seed=1)
    stat = bus.flood(bus.forge.strangers, rate=10_000)
    assert stat["keyed"] == 0
    assert stat["drop_unsigned"] + stat["drop_forged"] > 0, f"no flood reached the victim: {stat}"
    # the control: messages built the same way but signed with our key are delivered (so the
    # flood's were dropped for their signature, not for a mistake in how they were built)
    rng = bus.forge.rng
    for _ in range(20):
        datagram = bus.forge.keyed_message(rng.getrandbits(64), rng.getrandbits(32))
        flood_once(domain_id, datagram)
    assert bus.out.wait_for(lambda _: bus.stat()["keyed"] >= 20, 30.0), bus.stat()
    bus.check_delivered()
    bus.finish()


@pytest.mark.slow
def test_fragment_flood_stays_within_memory(processes: Processes, domain_id: int) -> None:
    bus = Scenario(processes, domain_id, seed=2)
    stat = bus.flood(bus.forge.fragments, rate=2_000)
    assert stat["held"] <= stat["budget"]
    # every fragment that reached the reassembler ends dropped: expired or evicted
    assert bus.out.wait_for(
        lambda _: bus.stat()["drop_incomplete"] + bus.stat()["drop_evicted"] > 0, 30.0
    ), f"no fragment reached the victim's reassembler: {bus.stat()}"
    bus.finish()


@pytest.mark.slow
def test_tiny_fragment_flood_stays_within_memory(processes: Processes, domain_id: int) -> None:
    bus = Scenario(processes, domain_id, seed=5)
    bus.flood(bus.forge.tiny_fragments, rate=20_000)
    assert bus.out.wait_for(lambda _: bus.stat()["drop_incomplete"] > 0, 30.0), (
        f"no fragment reached the victim's reassembler: {bus.stat()}"
    )
    bus.finish()


@pytest.mark.slow
def test_random_sender_flood_keeps_the_stream_tables_bounded(
    processes: Processes, domain_id: int
) -> None:
    bus = Scenario(processes, domain_id, seed=3)
    stat = bus.flood(bus.forge.senders, rate=10_000)
    assert stat["keyed"] > 0, f"none of the key holder's messages arrived: {stat}"
    assert stat["streams"] <= MAX_STREAMS, f"{stat['streams']:.0f} streams followed: {stat}"
    assert stat["retired"] <= MAX_RETIRED, f"{stat['retired']:.0f} streams retired: {stat}"
    bus.finish()


@pytest.mark.slow
def test_replays_and_forged_jumps_deliver_nothing_twice(
    processes: Processes, domain_id: int
) -> None:
    bus = Scenario(processes, domain_id, seed=4)
    captured = bus.capture()
    head = unpack(captured[0])
    assert head is not None
    talker = (head.sender, head.endpoint)
    forge = bus.forge
    jumps = 0

    def replays_and_jumps(n: int) -> tuple[int, bytes]:
        nonlocal jumps
        if n < 10_000:  # the first second: only replays (the stream stays the talker's)
            return CHANNEL, captured[n % len(captured)]
        if n % 4 == 3:  # the talker's id, a sequence number far ahead, signed: a key holder
            jumps += 1
            return CHANNEL, forge.keyed_message(talker[0], far_ahead(jumps), talker[1])
        if n % 4 == 2 and forge.sent_keyed:  # one of those jumps again
            return CHANNEL, forge.sent_keyed[forge.rng.randrange(len(forge.sent_keyed))]
        return CHANNEL, captured[n % len(captured)]  # the talker's own datagrams again

    stat = bus.flood(replays_and_jumps, rate=10_000)
    assert stat["keyed"] > 0, f"no forged jump arrived: {stat}"
    assert stat["drop_duplicates"] + stat["drop_stale"] > 0, f"no replay arrived: {stat}"
    bus.finish()


@pytest.mark.slow
def test_forged_near_jumps_do_not_inflate_the_loss_count(
    processes: Processes, domain_id: int
) -> None:
    """A key holder's sequence numbers half a loss window ahead of the talker's, in runs."""
    bus = Scenario(processes, domain_id, seed=6)
    head = unpack(bus.capture(want=10)[-1])
    assert head is not None

    def near(n: int) -> tuple[int, bytes]:
        return CHANNEL, bus.forge.keyed_message(head.sender, head.seq + 32768 + n, head.endpoint)

    # 300/s: batches of three consecutive numbers sent back to back, one batch every 10 ms, so
    # a forged gap is mostly "continued" by forged messages before the talker's next one
    stat = bus.flood(near, rate=300)
    assert stat["keyed"] > 0, f"no forged jump arrived: {stat}"
    bus.finish()  # the loss counted must not pass the real gaps


@pytest.mark.slow
def test_a_forged_jump_stamped_in_the_future_does_not_stop_the_talker(
    processes: Processes, domain_id: int
) -> None:
    """A key holder's few datagrams with the talker's id, far ahead, stamped an hour ahead."""
    bus = Scenario(processes, domain_id, seed=7)
    head = unpack(bus.capture(want=10)[-1])
    assert head is not None

    def future(n: int) -> tuple[int, bytes]:
        stamp = time.time_ns() + 3600 * 10**9
        return CHANNEL, bus.forge.keyed_message(head.sender, far_ahead(n), head.endpoint, stamp)

    bus.flood(future, rate=10)  # the talker's messages must keep arriving afterwards
    bus.finish()


def flood_once(domain: int, datagram: bytes) -> None:
    """Send one datagram to the topic's group."""
    addressing = Addressing(domain)
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
        sock.sendto(datagram, (addressing.group(CHANNEL), addressing.port))
