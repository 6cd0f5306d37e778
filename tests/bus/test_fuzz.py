"""Garbage on the wire: node processes must survive it and keep working.

Everything is sent to the test's own domain, from 127.0.0.1 with TTL 0. Most of the garbage
is signed with the test user's key, as a fuzzer holding the key would send it, so it reaches
every parser behind the MAC check; the rest is dropped by that check.
"""

from __future__ import annotations

import json
import random
import select
import socket
import struct
import time
from typing import TYPE_CHECKING

import pytest

from rosl.bus.fragment import MAX_MESSAGE_SIZE
from rosl.bus.header import HEADER, HEADER_SIZE, MAGIC, VERSION, Kind, topic_hash, type_hash, unpack
from rosl.bus.multicast import CHANNELS, Addressing, open_receiver
from rosl.bus.transport import channel_of
from rosl.graph.announce import DISCOVERY_TOPIC, DISCOVERY_TYPE
from tests.bus.helpers import (
    LISTENER,
    PROBE,
    TALKER,
    Lines,
    good_count,
    signed,
    unsigned_payload,
    wait_exit,
)

if TYPE_CHECKING:
    import subprocess

    from tests.conftest import Processes

TOPIC = "/fuzz_chatter"
TALKER_NAME = "fuzz_talker"
LISTENER_NAME = "fuzz_listener"
MAX_PAYLOAD = 65000 - HEADER_SIZE

DISCOVERY_HASH = topic_hash(DISCOVERY_TOPIC)
DISCOVERY_TYPE_HASH = type_hash(DISCOVERY_TYPE)


def fuzz_socket() -> socket.socket:
    """A socket whose multicast stays on this host: out of 127.0.0.1 with TTL 0."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
    return sock


def discovery_datagram(payload: bytes, sender: int, domain: int, seq: int = 1) -> bytes:
    head = HEADER.pack(
        MAGIC, VERSION, Kind.DISCOVERY, 0, 1, sender, seq, DISCOVERY_HASH, DISCOVERY_TYPE_HASH,
        0, 0, len(payload), time.time_ns(),
    )  # fmt: skip
    return signed(head + payload, domain)


class Node:
    """A node child process and its output."""

    def __init__(self, processes: Processes, code: str, name: str) -> None:
        self.name = name
        self.child: subprocess.Popen[str] = processes.python(code, name, TOPIC)
        self.out = Lines(self.child.stdout)
        self.err = Lines(self.child.stderr)

    def wait_up(self) -> None:
        assert self.out.wait_line("up", 20.0), f"{self.name} did not start: {self.err.rest(1.0)}"

    def stop(self) -> tuple[list[str], list[str]]:
        if self.child.poll() is None:
            self.child.send_signal(2)  # SIGINT: rosl's clean shutdown
        wait_exit(self.child, 10.0)
        return self.out.rest(3.0), self.err.rest(3.0)


def received(listener: Node) -> int:
    return good_count(listener.out.lines)


def capture_real_datagrams(domain: int, timeout: float = 20.0) -> tuple[list[bytes], list[bytes]]:
    """Genuine discovery and data datagrams of the running nodes (to truncate and mutate)."""
    addressing = Addressing(domain)
    disc = open_receiver(addressing, 0)
    data = open_receiver(addressing, channel_of(topic_hash(TOPIC)))
    hellos: list[bytes] = []
    messages: list[bytes] = []
    deadline = time.monotonic() + timeout
    try:
        while time.monotonic() < deadline and (len(hellos) < 2 or len(messages) < 5):
            ready, _, _ = select.select([disc, data], [], [], 0.1)
            for sock in ready:
                while True:
                    try:
                        datagram = sock.recv(65536)
                    except BlockingIOError:
                        break
                    head = unpack(datagram)
                    if head is None:
                        continue
                    if sock is disc and b'"op":"hello"' in datagram:
                        hellos.append(datagram)
                    elif sock is data and head.topic == topic_hash(TOPIC):
                        messages.append(datagram)
    finally:
        disc.close()
        data.close()
    return hellos, messages


def poison_json(rng: random.Random, hello: bytes) -> list[bytes]:
    """Discovery payloads that are valid datagrams but nonsense (or hostile) JSON."""
    real = json.loads(unsigned_payload(hello))
    liar = json.loads(unsigned_payload(hello))
    liar["process"]["sender"] = f"{rng.getrandbits(64):016x}"  # not the datagram's sender
    broken_nodes = json.loads(unsigned_payload(hello))
    broken_nodes["process"]["nodes"] = [{"name": 1}, None, [1, 2], {"endpoints": 5}]
    strange_known = json.loads(unsigned_payload(hello))
    strange_known["known"] = ["zz", 5, None, "0" * 5000]
    strange_known["reply_to"] = [5, "x:y", None, {"a": 1}]
    return [
        b'{"op":"hello","process":{}}',
        b'{"op":"hello"}',
        b'{"op":"hello","process":null}',
        b'{"op":"hello","process":[]}',
        b"\xff\xfe\xfd not utf-8 \xc3\x28",
        b"",
        b"{",
        b"null",
        b"[]",
        b'"op"',
        b"1e999",
        b'{"op":5}',
        b'{"op":["hello"]}',
        b'{"op":{"x":1}}',
        b'{"op":"bye"}',
        b'{"op":"bye","sender":"not hex"}',
        b'{"op":"bye","sender":12}',
        b'{"op":"query"}',
        b'{"op":"query","qid":"abc"}',
        b'{"op":"query","qid":null}',
        b'{"op":"query","qid":1e999}',  # a float infinity in plain JSON
        b'{"op":"query","qid":NaN}',
        b'{"op":"query","qid":"' + b"9" * 5000 + b'"}',
        b'{"op":"replay","topic":5,"target":"x"}',
        b'{"op":"unknown-op"}',
        b"[" * MAX_PAYLOAD,  # nested far deeper than the recursion limit
        b'{"a":' * 9000 + b"1" + b"}" * 9000,
        json.dumps({**real, "process": {**real["process"], "pid": 1e999}}).encode(),
        json.dumps(liar).encode(),
        json.dumps(broken_nodes).encode(),
        json.dumps(strange_known).encode(),
        rng.randbytes(2000),
    ]


def fuzz_datagrams(
    rng: random.Random, count: int, hellos: list[bytes], messages: list[bytes], domain: int
) -> list[tuple[int, bytes]]:
    """(channel, datagram) pairs: random, structured, truncated, mutated and poisoned.

    Structured, truncated and mutated ones are signed three times in four (a fuzzer with the
    key); the rest show the MAC check dropping them.
    """
    pool = rng.randbytes(2 * 65000)
    real = hellos + messages
    talker_sender = unpack(messages[0]).sender  # type: ignore[union-attr]
    topics = [topic_hash(TOPIC), DISCOVERY_HASH, topic_hash("/rosout"),
              topic_hash("/parameter_events")]  # fmt: skip
    types = [type_hash("std_msgs/msg/String"), DISCOVERY_TYPE_HASH]
    poison = poison_json(rng, hellos[0])
    out: list[tuple[int, bytes]] = []

    def channel_for(topic: int) -> int:
        return 0 if topic == DISCOVERY_HASH else channel_of(topic)

    def maybe_signed(datagram: bytes) -> bytes:
        return signed(datagram, domain) if rng.random() < 0.75 else datagram

    def random_length() -> int:
        return rng.choice([0, 1, 47, 48, 49, rng.randrange(0, 200), rng.randrange(0, 65001)])

    for _ in range(count):
        pick = rng.random()
        if pick < 0.25:  # pure random bytes
            size = random_length()
            start = rng.randrange(0, 65000)
            out.append((rng.randrange(CHANNELS + 1), pool[start : start + size]))
        elif pick < 0.6:  # a valid header with random fields
            cnt = rng.choice([1, 1, 2, 3, rng.randrange(1, 2**16)])
            topic = rng.choice([*topics, rng.getrandbits(64)])
            head = HEADER.pack(
                MAGIC,
                rng.choice([VERSION, VERSION, VERSION, VERSION, 0, 1, 3, 255]),
                rng.choice([*range(1, 6), rng.randrange(256)]),
                rng.randrange(256),
                cnt,
                rng.choice([talker_sender, rng.getrandbits(64)]),
                rng.getrandbits(32),
                topic,
                rng.choice([*types, rng.getrandbits(32)]),
                rng.choice([rng.randrange(cnt), rng.randrange(cnt), rng.randrange(2**16)]),
                rng.getrandbits(16),
                rng.choice([rng.getrandbits(32), MAX_MESSAGE_SIZE, rng.randrange(200_000), 0]),
                rng.choice([rng.getrandbits(63), time.time_ns()]),
            )
            size = min(random_length(), MAX_PAYLOAD)
            start = rng.randrange(0, 65000)
            out.append((channel_for(topic), maybe_signed(head + pool[start : start + size])))
        elif pick < 0.75:  # a truncated real datagram
            datagram = rng.choice(real)
            channel = 0 if datagram in hellos else channel_of(topic_hash(TOPIC))
            out.append((channel, maybe_signed(datagram[: rng.randrange(len(datagram))])))
        elif pick < 0.9:  # a real datagram with bit flips
            datagram = bytearray(rng.choice(real))
            channel = 0 if bytes(datagram) in hellos else channel_of(topic_hash(TOPIC))
            for _ in range(rng.randrange(1, 9)):
                bit = rng.randrange(len(datagram) * 8)
                datagram[bit // 8] ^= 1 << (bit % 8)
            out.append((channel, maybe_signed(bytes(datagram))))
        else:  # discovery JSON garbage, from a random or a real sender
            payload = rng.choice(poison)
            sender = rng.choice([talker_sender, rng.getrandbits(64)])
            out.append((0, discovery_datagram(payload, sender, domain, rng.getrandbits(32))))
    return out


def blast(domain: int, datagrams: list[tuple[int, bytes]], batch: int = 100) -> int:
    """Send every datagram to its group of ``domain``; return how many went out.

    A short pause after every ``batch`` datagrams lets the receivers actually read (and so
    parse) most of them instead of the kernel dropping them from full receive buffers.
    """
    addressing = Addressing(domain)
    sock = fuzz_socket()
    sent = 0
    try:
        for number, (channel, datagram) in enumerate(datagrams, 1):
            if number % batch == 0:
                time.sleep(0.01)
            try:
                sock.sendto(datagram, (addressing.group(channel), addressing.port))
                sent += 1
            except OSError:
                pass  # e.g. a full send buffer: the test only needs thousands to arrive
    finally:
        sock.close()
    return sent


def probe_graph(processes: Processes, *names: str) -> list[str]:
    probe = processes.python(PROBE, *names)
    out, err = Lines(probe.stdout), Lines(probe.stderr)
    out.wait_for(lambda lines: any(x in ("found", "missing") for x in lines), 40.0)
    wait_exit(probe, 10.0)
    return [*out.rest(2.0), *err.rest(2.0)]


def assert_no_traceback(name: str, err: list[str]) -> None:
    text = "\n".join(err)
    assert "Traceback" not in text, f"{name} raised:\n{text[-3000:]}"
    assert "Exception in thread" not in text, f"{name} lost a thread:\n{text[-3000:]}"


@pytest.mark.slow
def test_nodes_survive_thousands_of_garbage_datagrams(processes: Processes, domain_id: int) -> None:
    talker = Node(processes, TALKER, TALKER_NAME)
    listener = Node(processes, LISTENER, LISTENER_NAME)
    talker.wait_up()
    listener.wait_up()
    assert listener.out.wait_for(lambda _: received(listener) >= 10, 20.0), (
        f"no messages before fuzzing: {listener.err.rest(1.0)}"
    )
    hellos, messages = capture_real_datagrams(domain_id)
    assert hellos, "no discovery datagram captured"
    assert messages, "no data datagram captured"

    rng = random.Random(20240611)
    datagrams = fuzz_datagrams(rng, 20_000, hellos, messages, domain_id)
    assert blast(domain_id, datagrams) >= 19_000

    assert talker.child.poll() is None, f"talker died: {talker.err.rest(1.0)}"
    assert listener.child.poll() is None, f"listener died: {listener.err.rest(1.0)}"
    after_fuzz = received(listener)
    assert listener.out.wait_for(lambda _: received(listener) >= after_fuzz + 50, 20.0), (
        f"listener stopped receiving after the fuzzing (at {after_fuzz}): {listener.err.rest(1.0)}"
    )

    found = probe_graph(processes, f"/{TALKER_NAME}", f"/{LISTENER_NAME}")
    assert talker.child.poll() is None
    assert listener.child.poll() is None

    _, talker_err = talker.stop()
    listener_out, listener_err = listener.stop()
    assert "found" in found, (
        f"a fresh process cannot discover both nodes: {found}\n"
        f"talker stderr: {talker_err[-6:]}\nlistener stderr: {listener_err[-6:]}"
    )
    assert_no_traceback("talker", talker_err)
    assert_no_traceback("listener", listener_err)
    final = [x for x in listener_out if x.startswith("final ")]
    assert final, f"listener did not shut down cleanly: {listener_out[-5:]} {listener_err[-5:]}"


# --- single poisonous discovery datagrams (each one is in the fuzz mix above) ------------------

POISON = {
    "deep-list": b"[" * MAX_PAYLOAD,
    "deep-object": b'{"a":' * 9000 + b"1" + b"}" * 9000,
    "query-qid-1e999": b'{"op":"query","qid":1e999}',
    "hello-pid-1e999": None,  # built from the node's own hello (its sender must match)
    "lying-hello": None,
    "empty-process": b'{"op":"hello","process":{}}',
    "invalid-utf8": b"\xff\xfe\xfd \xc3\x28",
}


@pytest.mark.parametrize("case", list(POISON))
def test_discovery_survives_one_poisonous_datagram(
    processes: Processes, domain_id: int, case: str
) -> None:
    talker = Node(processes, TALKER, TALKER_NAME)
    talker.wait_up()
    hellos, messages = capture_real_datagrams(domain_id)
    assert hellos
    assert messages
    sender = unpack(hellos[0]).sender  # type: ignore[union-attr]
    payload = POISON[case]
    if payload is None:
        record = json.loads(unsigned_payload(hellos[0]))
        if case == "hello-pid-1e999":
            record["process"]["pid"] = 1e999  # json.dumps writes Infinity
            payload = json.dumps(record).replace("Infinity", "1e999").encode()
        else:
            record["process"]["sender"] = f"{sender ^ 0xFF:016x}"
            payload = json.dumps(record).encode()
    blast(domain_id, [(0, discovery_datagram(payload, sender ^ 1, domain_id, 7))])
    time.sleep(0.3)  # let it be handled before the probe starts asking
    assert talker.child.poll() is None
    found = probe_graph(processes, f"/{TALKER_NAME}")
    _, err = talker.stop()
    assert "found" in found, f"discovery of the node stopped working after {case!r}: {err[-12:]}"
    assert_no_traceback("talker", err)


def test_data_channel_garbage_for_a_subscribed_topic(processes: Processes, domain_id: int) -> None:
    """Valid headers for the listener's topic and type with random payloads (undecodable CDR)."""
    talker = Node(processes, TALKER, TALKER_NAME)
    listener = Node(processes, LISTENER, LISTENER_NAME)
    talker.wait_up()
    listener.wait_up()
    assert listener.out.wait_for(lambda _: received(listener) >= 10, 20.0)
    rng = random.Random(5)
    topic, type_ = topic_hash(TOPIC), type_hash("std_msgs/msg/String")
    datagrams = []
    for seq in range(2000):
        payload = rng.randbytes(rng.choice([0, 1, 3, 4, 5, 8, rng.randrange(0, 300)]))
        head = HEADER.pack(
            MAGIC, VERSION, Kind.DATA, 0, 1, 0xBAD5EED, seq, topic, type_, 0, 1, len(payload),
            time.time_ns(),
        )  # fmt: skip
        datagrams.append((channel_of(topic), signed(head + payload, domain_id)))
    # a CDR string that claims 4 GiB
    cdr = b"\x00\x01\x00\x00" + struct.pack("<I", 0xFFFFFFFF) + b"abc"
    head = HEADER.pack(
        MAGIC, VERSION, Kind.DATA, 0, 1, 0xBAD5EED, 9999, topic, type_, 0, 1, len(cdr),
        time.time_ns(),
    )  # fmt: skip
    datagrams.append((channel_of(topic), signed(head + cdr, domain_id)))
    blast(domain_id, datagrams)
    after = received(listener)
    assert listener.out.wait_for(lambda _: received(listener) >= after + 30, 20.0), (
        f"listener stopped: {listener.err.rest(1.0)}"
    )
    assert listener.child.poll() is None
    out, err = listener.stop()
    talker.stop()
    assert_no_traceback("listener", err)
    assert any(x.startswith("final ") for x in out)
