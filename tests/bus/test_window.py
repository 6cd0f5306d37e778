"""Sequence windows: nothing delivered twice, loss counted exactly, no datagram poisons a stream,
and the state strangers can make a reader keep is bounded."""

from __future__ import annotations

import os
import random
import threading
import time
from typing import TYPE_CHECKING

import pytest

from rosl.bus import auth, wire
from rosl.bus.header import HEADER, MAGIC, VERSION, Flags, Kind, topic_hash, type_hash
from rosl.bus.multicast import Addressing, MulticastTransport
from rosl.bus.transport import channel_of
from rosl.bus.wire import Reader
from tests.bus.helpers import Collector

if TYPE_CHECKING:
    from collections.abc import Iterator

TOPIC = "/window_test"
TOPIC_HASH = topic_hash(TOPIC)
TYPE_HASH = type_hash("std_msgs/msg/String")
CHANNEL = channel_of(TOPIC_HASH)
SENDER = 0x5E55_1011
KEY = b"window test key"


class Wire:
    """Hand-made signed datagrams onto a real socket, and a keyed reader collecting them."""

    def __init__(self, domain: int) -> None:
        self.auth = auth.Auth(KEY, domain, "test")
        self.tx = MulticastTransport(Addressing(domain), None)
        self.rx = MulticastTransport(Addressing(domain), None)
        self.reader = Reader(self.auth)
        self.reader.wanted.add(TOPIC_HASH)
        self.logged: list[str] = []
        self.reader.log = self.logged.append
        self.collector = Collector(self.reader, self.rx.open(CHANNEL))

    def datagram(
        self,
        seq: int,
        payload: bytes = b"m",
        *,
        sender: int = SENDER,
        endpoint: int = 1,
        kind: int = Kind.DATA,
        stamp: int | None = None,
        count: int = 1,
        index: int = 0,
        total: int | None = None,
    ) -> bytes:
        head = HEADER.pack(
            MAGIC, VERSION, kind, Flags.SIGNED, count, sender, seq, TOPIC_HASH, TYPE_HASH,
            index, endpoint, len(payload) if total is None else total,
            time.time_ns() if stamp is None else stamp,
        )  # fmt: skip
        return head + payload + self.auth.mac(head + payload)

    def send(self, *datagrams: bytes) -> None:
        for datagram in datagrams:
            self.tx.send(CHANNEL, [datagram])

    def marker(self, seq: int, sender: int = SENDER) -> None:
        """Send a last datagram and wait for it: everything before it was read."""
        self.send(self.datagram(seq, b"marker", sender=sender))
        assert self.collector.wait_for(
            lambda got: any(bytes(d.payload) == b"marker" and d.seq == seq for d in got), 10.0
        ), "the marker never arrived"

    def seqs(self) -> list[int]:
        return [d.seq for d in self.collector.snapshot() if bytes(d.payload) != b"marker"]

    def close(self) -> None:
        self.collector.stop()
        self.tx.close()
        self.rx.close()


@pytest.fixture
def bus(domain_id: int) -> Iterator[Wire]:
    w = Wire(domain_id)
    try:
        yield w
    finally:
        w.close()


def test_a_resent_datagram_is_delivered_once(bus: Wire) -> None:
    bus.send(bus.datagram(1))
    for _ in range(30):
        bus.send(bus.datagram(2, b"again"))  # the same message, 30 times
    bus.marker(3)
    assert bus.seqs() == [1, 2]
    assert bus.reader.duplicates == 29  # the first of the 30 was new
    assert bus.reader.lost() == 0


def test_a_replayed_old_message_is_not_delivered_again(bus: Wire) -> None:
    old = [bus.datagram(seq) for seq in range(1, 201)]
    bus.send(*old[:100])
    bus.marker(201)
    bus.send(*old[:100])  # replayed, inside the window
    bus.send(bus.datagram(5000))  # the stream moves on by more than the duplicate window
    bus.send(old[99])  # seq 100 again, now far behind the window: stale
    bus.marker(5001)
    assert bus.seqs() == [*range(1, 101), 5000]
    assert bus.reader.duplicates == 100
    assert bus.reader.stale == 1


def test_gaps_are_counted_exactly_and_a_late_message_takes_its_gap_back(bus: Wire) -> None:
    for seq in [*range(1, 11), *range(16, 21)]:  # 11..15 missing
        bus.send(bus.datagram(seq))
    bus.marker(21)
    assert bus.reader.lost() == 5
    bus.send(bus.datagram(13))  # one of them arrives late
    bus.marker(22)
    assert bus.reader.lost() == 4
    assert 13 in bus.seqs()


def test_one_forged_jump_neither_poisons_the_loss_count_nor_stops_the_stream(bus: Wire) -> None:
    for seq in range(1, 11):
        bus.send(bus.datagram(seq))
    bus.marker(11)
    bus.send(bus.datagram(11 + 0x7FFFFFF0))  # signed by a key holder, sequence far ahead
    for seq in range(12, 20):  # the real publisher goes on
        bus.send(bus.datagram(seq))
    bus.marker(20)
    assert bus.reader.lost() == 0
    # the forged message itself is delivered (a key holder can send one), nothing is lost
    assert bus.seqs() == [*range(1, 11), 11 + 0x7FFFFFF0, *range(12, 20)]
    for seq in (22, 23):  # a real gap after the jump is still counted
        bus.send(bus.datagram(seq))
    bus.marker(24)
    assert bus.reader.lost() == 1
    assert len(bus.logged) == 1  # once per stream, however often it jumps
    assert "jumped" in bus.logged[0]


def test_an_old_datagram_opening_a_stream_is_stale(bus: Wire) -> None:
    old = time.time_ns() - wire.FRESH_NS - 1_000_000_000
    bus.send(bus.datagram(1, sender=0x01D, stamp=old))
    bus.send(bus.datagram(1, sender=0x0FF, stamp=time.time_ns() + 2 * wire.FRESH_NS))
    bus.marker(1)
    assert bus.seqs() == []
    assert bus.reader.stale == 2


def test_a_forgotten_stream_stays_protected_and_resumes_its_loss_count(bus: Wire) -> None:
    captured = [bus.datagram(seq) for seq in range(1, 6)]
    bus.send(*captured)
    bus.marker(6)
    bus.reader.forget(SENDER)  # the process said goodbye
    bus.reader._next_housekeeping = 0  # the next look retires it now
    bus.send(bus.datagram(1, sender=0x0DD))  # a look at the socket
    assert bus.collector.wait_for(lambda _: (SENDER, 1) not in bus.reader.streams, 10.0)
    bus.send(*captured)  # replayed after the state was retired
    bus.send(bus.datagram(9))  # the stream's next message (7 and 8 lost)
    bus.marker(10)
    # 1-5, the look (seq 1 of another sender) and 9: the replay was not delivered
    assert bus.seqs() == [1, 2, 3, 4, 5, 1, 9]
    assert bus.reader.lost() == 2
    assert bus.reader.duplicates == 5  # the stream came back with its window


def test_service_streams_are_told_apart_by_target(bus: Wire) -> None:
    # a server numbers its responses to all clients with one counter: a client that calls
    # rarely sees numbers far apart, and each target's stream must stand on its own
    from rosl.bus.header import ADDRESS

    def response(seq: int, target: int, stamp: int) -> bytes:
        body = ADDRESS.pack(0xC11E, target, seq) + b"answer"
        head = HEADER.pack(
            MAGIC, VERSION, Kind.RESPONSE, Flags.SIGNED | Flags.ADDRESSED, 1, SENDER, seq,
            TOPIC_HASH, TYPE_HASH, 0, 4, len(body), stamp,
        )  # fmt: skip
        return head + body + bus.auth.mac(head + body)

    early = time.time_ns()
    late = response(3000, 11, early + 1_000_000)
    bus.send(late, late)  # twice: the second is a duplicate
    bus.send(response(1, 10, early))  # far behind 3000 and older: only its own stream takes it
    bus.marker(1)
    got = [(d.seq, d.address) for d in bus.collector.snapshot() if d.kind == Kind.RESPONSE]
    assert got == [(3000, (0xC11E, 11, 3000)), (1, (0xC11E, 10, 1))]
    assert bus.reader.duplicates == 1


def test_every_datagram_must_be_fresh(bus: Wire) -> None:
    now = time.time_ns()
    for seq in (1, 2, 4):  # 3 is lost
        bus.send(bus.datagram(seq))
    bus.send(bus.datagram(3, stamp=now - wire.FRESH_NS - 1_000_000_000))  # replayed much later
    bus.send(bus.datagram(5, stamp=now + wire.FRESH_NS + 1_000_000_000))  # from the future
    bus.send(bus.datagram(6))
    bus.marker(7)
    assert bus.seqs() == [1, 2, 4, 6]
    assert bus.reader.stale == 2
    assert bus.reader.lost() == 2  # 3 and 5


def test_a_stream_first_heard_must_be_younger_than_the_reader(bus: Wire) -> None:
    born = bus.reader._born
    captured = bus.datagram(1, sender=0xCA97, stamp=born - 5_000_000_000)  # before we started
    bus.send(captured)
    bus.marker(1)
    assert bus.seqs() == []
    assert bus.reader.stale == 1


def test_an_old_fragment_does_not_end_a_newer_message(bus: Wire) -> None:
    chunk = bytes(range(256)) * 100

    def fragment(seq: int, index: int) -> bytes:
        return bus.datagram(seq, chunk, kind=Kind.REQUEST, endpoint=3, count=2,
                            index=index, total=2 * len(chunk))  # fmt: skip

    bus.send(fragment(3, 0), fragment(3, 1))  # request 3, whole
    bus.send(fragment(5, 0))  # request 5 starts
    bus.send(fragment(3, 1))  # a fragment of request 3 again (replayed)
    bus.send(fragment(5, 1))  # request 5 completes
    bus.marker(1)
    got = [d.seq for d in bus.collector.snapshot() if d.kind == Kind.REQUEST]
    assert got == [3, 5]
    assert bus.reader.reassembler.incomplete == 0


def test_a_retired_stream_resumes_after_its_senders_clock_stepped_back(bus: Wire) -> None:
    now = time.time_ns()
    bus.send(bus.datagram(1, stamp=now), bus.datagram(2, stamp=now))
    bus.marker(3)
    bus.reader.forget(SENDER)
    bus.reader._next_housekeeping = 0
    bus.send(bus.datagram(1, sender=0x0DD))  # a look at the socket: retires the stream
    assert bus.collector.wait_for(lambda _: (SENDER, 1) not in bus.reader.streams, 10.0)
    stepped_back = now - 5_000_000_000  # the sender's clock went back 5 s (still fresh)
    bus.send(bus.datagram(4, stamp=stepped_back), bus.datagram(5, stamp=stepped_back))
    bus.marker(6)
    assert [s for s in bus.seqs() if s > 3] == [4, 5]


# --- bounded state ------------------------------------------------------------------------------


def test_random_sender_ids_cannot_grow_the_stream_table(
    bus: Wire, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(wire, "MAX_STREAMS", 500)
    monkeypatch.setattr(wire, "MAX_RETIRED", 700)
    rng = random.Random(7)
    for number in range(3000):
        bus.send(bus.datagram(rng.getrandbits(32), sender=rng.getrandbits(64)))
        if number % 200 == 199:
            time.sleep(0.02)  # let the reader keep up (loss is fine: the bound is the point)
    bus.marker(1)
    assert len(bus.reader.streams) <= 500
    assert len(bus.reader._retired) <= 700
    assert bus.reader.retired > 0
    assert bus.reader.received() == len(bus.collector.snapshot())  # retired counts folded in


def test_fragments_from_random_senders_stay_inside_the_reassembly_budget(bus: Wire) -> None:
    bus.reader.reassembler.budget = 4 * 1024 * 1024
    rng = random.Random(11)
    chunk = os.urandom(60_000)
    peak = 0
    for number in range(400):  # fragment 0 of a 3-fragment message, from 400 senders
        bus.send(bus.datagram(1, chunk, sender=rng.getrandbits(64), count=3, total=180_000))
        if number % 50 == 49:
            time.sleep(0.02)
            peak = max(peak, bus.reader.reassembler.held)
    bus.marker(1)
    peak = max(peak, bus.reader.reassembler.held)
    assert peak <= 4 * 1024 * 1024
    assert bus.reader.reassembler.evicted > 0


def test_lazily_mapped_messages_are_charged_as_they_fill() -> None:
    from rosl.bus.fragment import Reassembler
    from rosl.bus.header import Header

    r = Reassembler(budget=8 * 1024 * 1024)
    total = 64 * 1024 * 1024 // 16  # 4 MiB: a lazily mapped buffer
    chunk = 64_000
    count = -(-total // chunk)

    for sender in range(100):  # 100 messages started: only what arrived is charged
        header = Header(MAGIC, VERSION, 1, 0, count, sender, 1, 1, 1, 0, 1, total, 0)
        assert r.add(header, memoryview(bytes(chunk)), 0) is None
    assert r.held <= 8 * 1024 * 1024
    assert r.pending == 100
    assert r.evicted == 0
    too_big = Reassembler(budget=1024 * 1024)
    too_big.add(
        Header(MAGIC, VERSION, 1, 0, count, 1, 1, 1, 1, 0, 1, total, 0),
        memoryview(bytes(chunk)),
        0,
    )
    assert (too_big.oversize, too_big.pending) == (1, 0)


def test_counting_loss_while_streams_come_and_go_never_fails() -> None:
    """The discovery thread counts loss (announcing) while the polling thread adds streams."""
    reader = Reader(None)
    reader.want_all = True
    errors: list[BaseException] = []
    stop = threading.Event()

    def count() -> None:
        try:
            while not stop.is_set():
                reader.lost(TOPIC_HASH)
                reader.received()
        except BaseException as err:
            errors.append(err)

    counters = [threading.Thread(target=count) for _ in range(2)]
    for thread in counters:
        thread.start()
    now = time.time_ns()
    rng = random.Random(3)
    try:
        for sender in range(60_000):
            stats = wire.StreamStats(TOPIC_HASH, last_received=now)
            reader.streams[(rng.getrandbits(64), sender & 0xFFFF)] = stats
            if sender % 5000 == 4999:
                reader._housekeeping(now + wire.SILENT_NS + 1)  # retire them all
    finally:
        stop.set()
        for thread in counters:
            thread.join(10)
    assert errors == []


def test_a_forged_detour_leaves_no_loss_once_the_real_stream_goes_on(bus: Wire) -> None:
    for seq in range(1, 11):
        bus.send(bus.datagram(seq))
    forged = [bus.datagram(10 + 30_000 + n) for n in range(3)]  # a key holder's run, ahead
    bus.send(*forged)
    bus.marker(11)  # the real stream goes on
    assert bus.reader.lost() == 0
    bus.send(bus.datagram(13))  # a real gap of one, after the detour
    bus.marker(14)
    assert bus.reader.lost() == 1
    bus.send(forged[0])  # the forged detour replayed: its stamp is older than the stream's
    bus.marker(15)
    assert bus.reader.lost() == 1
    assert bus.reader.stale == 1
    assert bus.seqs().count(30_010) == 1


def test_a_real_burst_of_loss_is_counted_once_the_stream_goes_on(bus: Wire) -> None:
    bus.send(bus.datagram(1))
    bus.send(bus.datagram(5002))  # 5000 lost at once (more than the duplicate window)
    bus.marker(5003)
    assert bus.reader.lost() == 5000
    bus.send(bus.datagram(4500))  # one of them, late, inside the window
    bus.marker(5004)
    assert bus.reader.lost() == 4999


def test_big_gaps_one_after_another_count_only_the_missing_messages(bus: Wire) -> None:
    # a recorder falling behind a flat-out publisher: bursts of loss between runs it received
    received = [*range(1, 11), *range(2001, 2011), *range(4001, 4011)]
    for seq in received:
        bus.send(bus.datagram(seq))
    bus.marker(4011)
    assert bus.reader.received() == len(received) + 1
    assert bus.reader.lost() == 1990 + 1990  # 11..2000 and 2011..4000, nothing received


def test_a_forged_jump_stamped_ahead_does_not_hold_the_real_stream_back(bus: Wire) -> None:
    for seq in (1, 2):
        bus.send(bus.datagram(seq))
    ahead = time.time_ns() + 20_000_000_000  # 20 s ahead: still fresh
    bus.send(bus.datagram(2_000_000_000, stamp=ahead))  # a key holder's far jump
    bus.send(bus.datagram(1_000_000_000, stamp=ahead))  # and another, far from the first
    for seq in (3, 4):
        bus.send(bus.datagram(seq))
    bus.marker(5)
    assert [s for s in bus.seqs() if s < 100] == [1, 2, 3, 4]
    assert bus.reader.lost() == 0


# --- the receive path's common case against the window's rules ----------------------------------

MARK_SENDER = 0xEEEE  # a stream of its own for the markers of the tests below
CHUNK = 400  # datagrams sent before waiting for the reader (no socket overflows)


def _send_in_chunks(bus: Wire, datagrams: list[bytes]) -> None:
    for start in range(0, len(datagrams), CHUNK):
        bus.send(*datagrams[start : start + CHUNK])
        bus.marker(start // CHUNK + 1, sender=MARK_SENDER)


def _arrivals(rng: random.Random, senders: list[int], length: int) -> list[tuple[int, int]]:
    """(sender, seq) in arrival order: mostly in line, with gaps, repeats, late and far ones."""
    following = dict.fromkeys(senders, 1)
    heard: dict[int, list[int]] = {s: [] for s in senders}
    order = []
    for _ in range(length):
        sender = rng.choice(senders)
        roll = rng.random()
        if roll < 0.10:  # a gap
            following[sender] += rng.randint(1, 5)
        elif roll < 0.12:  # a gap longer than the duplicate window
            following[sender] += wire.DUP_WINDOW + rng.randint(1, 50)
        if 0.12 <= roll < 0.22 and heard[sender]:  # a repeat, or an old one after a big gap
            seq = rng.choice(heard[sender][-60:])
        elif 0.22 <= roll < 0.27 and following[sender] > 20:  # late (maybe never sent before)
            seq = following[sender] - rng.randint(1, 20)
        else:
            seq = following[sender]
            following[sender] += 1
        heard[sender].append(seq)
        order.append((sender, seq))
    return order


def test_the_receive_path_follows_the_window_rules_for_many_streams(bus: Wire) -> None:
    # the reader takes a plain message that goes on in line without calling place_in_window:
    # every count must come out as place_in_window, message by message, would make them
    rng = random.Random(1234)
    senders = [0x5EED_0000 + i for i in range(20)]
    order = _arrivals(rng, senders, 3000)
    base = time.time_ns()
    stamps = [base + i * 1000 for i in range(len(order))]  # each newer than the one before
    _send_in_chunks(bus, [
        bus.datagram(seq, b"m", sender=sender, stamp=stamp)
        for (sender, seq), stamp in zip(order, stamps, strict=True)
    ])  # fmt: skip
    expected: dict[int, wire.StreamStats] = {}
    delivered, refused = [], {wire.DUPLICATE: 0, wire.STALE: 0}
    now = time.time_ns()
    for (sender, seq), stamp in zip(order, stamps, strict=True):
        stats = expected.get(sender)
        if stats is None:
            stats = expected[sender] = wire.StreamStats(TOPIC_HASH, last_seq=seq - 1)
        verdict = wire.place_in_window(stats, seq, stamp, now, True)
        if verdict <= 0:
            delivered.append((sender, seq))
        else:
            refused[verdict] += 1
    got = [(d.sender, d.seq) for d in bus.collector.snapshot() if d.sender in expected]
    assert got == delivered
    fields = ("received", "lost", "pending", "last_seq", "seen", "jumps", "run", "stamp", "left")
    for sender, stats in expected.items():
        mine = bus.reader.streams[(sender, 1)]
        assert [getattr(mine, f) for f in fields] == [getattr(stats, f) for f in fields]
    assert bus.reader.lost(TOPIC_HASH) == sum(s.lost for s in expected.values()) > 0
    assert bus.reader.duplicates == refused[wire.DUPLICATE] > 0
    assert bus.reader.stale == refused[wire.STALE]
    assert any(s.jumps for s in expected.values())  # (the test takes every way through)
    assert any(s.pending for s in expected.values()) or any(s.left for s in expected.values())


def test_loss_from_many_publishers_is_what_was_never_sent(bus: Wire) -> None:
    rng = random.Random(99)
    senders = [0xFA11_0000 + i for i in range(20)]
    kept = {s: [q for q in range(1, 201) if q in (1, 200) or rng.random() > 0.1] for s in senders}
    queues = {s: list(seqs) for s, seqs in kept.items()}
    datagrams, repeats = [], 0
    while queues:  # the publishers interleaved, each in order, some datagrams twice
        sender = rng.choice(sorted(queues))
        seq = queues[sender].pop(0)
        datagrams.append(bus.datagram(seq, sender=sender))
        if rng.random() < 0.05:
            datagrams.append(bus.datagram(seq, b"again", sender=sender))
            repeats += 1
        if not queues[sender]:
            del queues[sender]
    _send_in_chunks(bus, datagrams)
    never_sent = {s: 200 - len(seqs) for s, seqs in kept.items()}
    assert bus.reader.lost(TOPIC_HASH) == sum(never_sent.values()) > 0
    markers = bus.reader.streams[(MARK_SENDER, 1)].received
    assert bus.reader.received(TOPIC_HASH) - markers == sum(map(len, kept.values()))
    assert bus.reader.duplicates == repeats
    by_publisher = {key[0]: lost for key, lost in bus.reader.lost_by_publisher(TOPIC_HASH).items()}
    assert by_publisher == {s: n for s, n in never_sent.items() if n}
    got = sorted((d.sender, d.seq) for d in bus.collector.snapshot() if d.sender in kept)
    assert got == sorted((s, q) for s, seqs in kept.items() for q in seqs)
