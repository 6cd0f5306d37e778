"""Coalescing writers: many small messages per datagram, unpacked into ordinary deliveries."""

from __future__ import annotations

import select
import time
from typing import TYPE_CHECKING

import pytest

from rosl.bus.auth import MAC_SIZE
from rosl.bus.coalesce import RECORD, Flusher, split_records
from rosl.bus.header import HEADER, HEADER_SIZE, MAGIC, VERSION, Flags, Kind, topic_hash
from rosl.bus.multicast import Addressing, MulticastTransport
from tests.bus.test_wire import ENDPOINT, SENDER, TOPIC, Bus, payload_of

if TYPE_CHECKING:
    import socket
    from collections.abc import Iterator

    from rosl.bus.wire import Delivery


LIMIT = 16384  # the batch bound the tests give the writer


class Counted:
    """A bus whose writer coalesces, plus a second socket on the channel counting datagrams."""

    def __init__(self, domain: int, delay_s: float = 0.001, limit: int = LIMIT) -> None:
        self.bus = Bus(domain)
        self.flusher = Flusher(delay_s)
        self.bus.writer.coalesce(self.flusher, limit)
        self.spy = MulticastTransport(Addressing(domain))
        self.spy_socket: socket.socket = self.spy.open(self.bus.writer.channel)

    def datagrams(self, settle: float = 0.2) -> list[bytes]:
        """Every datagram the spy socket holds (waiting up to ``settle`` s for stragglers)."""
        out: list[bytes] = []
        while select.select([self.spy_socket], [], [], settle)[0]:
            out.append(self.spy_socket.recv(65536))
        return out

    def close(self) -> None:
        self.flusher.close()
        self.bus.close()
        self.spy.close()


@pytest.fixture
def counted(domain_id: int) -> Iterator[Counted]:
    c = Counted(domain_id)
    try:
        yield c
    finally:
        c.close()


def batched_records(datagrams: list[bytes]) -> list[list[tuple[int, int, bytes]]]:
    """The (seq, stamp, bytes) records of each datagram, checking each is a well-formed batch."""
    out = []
    for datagram in datagrams:
        assert datagram[:2] == MAGIC
        assert HEADER.unpack_from(datagram)[3] & Flags.BATCH
        end = len(datagram) - (MAC_SIZE if HEADER.unpack_from(datagram)[3] & Flags.SIGNED else 0)
        records = split_records(memoryview(datagram)[HEADER_SIZE:end])
        out.append([(seq, stamp, bytes(body)) for seq, stamp, body in records])
    return out


def send_thousand(counted: Counted) -> tuple[list[bytes], list[int]]:
    """Send 1000 small messages with explicit stamps; return the payloads and stamps."""
    payloads = [payload_of(64, seed=n) for n in range(1000)]
    start = time.time_ns()  # stamps are checked for freshness when a stream opens
    stamps = [start + n for n in range(1000)]
    for payload, stamp in zip(payloads, stamps, strict=True):
        counted.bus.writer.send(payload, stamp=stamp)
    return payloads, stamps


def assert_whole_and_in_order(
    got: list[Delivery], payloads: list[bytes], stamps: list[int]
) -> None:
    assert [bytes(d.payload) for d in got] == payloads
    assert [d.seq for d in got] == list(range(1, len(payloads) + 1))
    assert [d.stamp for d in got] == stamps
    assert {(d.kind, d.sender, d.endpoint, d.flags) for d in got} == {
        (Kind.DATA, SENDER, ENDPOINT, 0)
    }


def test_small_messages_share_datagrams_and_arrive_whole_in_order(counted: Counted) -> None:
    # What holds however the flusher thread is scheduled: every message arrives once, whole
    # and in order, in batch datagrams that keep the size bound and carry the records in order.
    payloads, stamps = send_thousand(counted)
    got = counted.bus.collector.wait_count(1000, timeout=20.0)
    assert_whole_and_in_order(got, payloads, stamps)
    assert counted.bus.reader.lost() == 0
    batches = batched_records(counted.datagrams())
    assert all(sum(RECORD.size + len(r[2]) for r in b) <= LIMIT for b in batches)
    records = [r for b in batches for r in b]
    assert records == [(n + 1, s, p) for n, (s, p) in enumerate(zip(stamps, payloads, strict=True))]


def test_plain_sends_share_datagrams_and_a_big_one_keeps_its_place(counted: Counted) -> None:
    payloads = [payload_of(64, seed=n) for n in range(300)]
    payloads[150] = payload_of(LIMIT + 1, seed=150)  # too big for a batch
    numbers = [counted.bus.writer.send_plain(p) for p in payloads]
    got = counted.bus.collector.wait_count(300, timeout=20.0)
    assert [bytes(d.payload) for d in got] == payloads
    assert [d.seq for d in got] == numbers == list(range(1, 301))
    assert all(d.flags == 0 for d in got)
    datagrams = counted.datagrams()
    batches = batched_records([d for d in datagrams if HEADER.unpack_from(d)[3] & Flags.BATCH])
    assert [r[0] for b in batches for r in b] == [n for n in numbers if n != 151]


def test_only_the_size_bound_splits_batches_while_the_delay_has_not_passed(
    domain_id: int,
) -> None:
    # With a delay that cannot pass during the test, the datagram count is exact: full
    # batches, then the rest when the flusher is told to send what is pending.
    counted = Counted(domain_id, delay_s=60.0)
    try:
        payloads, stamps = send_thousand(counted)
        counted.flusher.flush()
        got = counted.bus.collector.wait_count(1000, timeout=20.0)
        assert_whole_and_in_order(got, payloads, stamps)
        batches = batched_records(counted.datagrams())
        per_datagram = LIMIT // (RECORD.size + 64)
        assert [len(b) for b in batches] == [per_datagram] * (1000 // per_datagram) + [
            1000 % per_datagram
        ]
        assert len(batches) < 1000 // 10  # several messages a datagram, not one each
    finally:
        counted.close()


def test_a_lone_message_goes_out_within_the_delay_without_further_sends(
    counted: Counted,
) -> None:
    counted.bus.writer.send(b"alone")  # nothing fills the batch: only the flusher can send it
    got = counted.bus.collector.wait_count(1, timeout=20.0)
    assert [bytes(d.payload) for d in got] == [b"alone"]


def test_a_big_message_after_small_ones_keeps_its_place(counted: Counted) -> None:
    big = payload_of(200_000, seed=9)
    counted.bus.writer.send(b"one")
    counted.bus.writer.send(b"two")
    counted.bus.writer.send(big)  # fragmented: the batch must go first
    counted.bus.writer.send(b"three")
    got = counted.bus.collector.wait_count(4, timeout=20.0)
    assert [bytes(d.payload) for d in got] == [b"one", b"two", big, b"three"]
    assert [d.seq for d in got] == [1, 2, 3, 4]


def test_send_all_numbers_batches_and_bounds_like_one_send_each(domain_id: int) -> None:
    # a thousand messages in one call: the same numbers, size bound and splits as send()'s
    counted = Counted(domain_id, delay_s=60.0)
    try:
        writer = counted.bus.writer
        writer.send(b"first")
        payloads = [payload_of(64, seed=n) for n in range(1000)]
        writer.send_all(payloads)
        writer.send_all([payload_of(200_000, seed=9), b"after"])  # too big: each its own send
        counted.flusher.flush()
        got = counted.bus.collector.wait_count(1003, timeout=20.0)
        everything = [b"first", *payloads, payload_of(200_000, seed=9), b"after"]
        assert [bytes(d.payload) for d in got] == everything
        assert [d.seq for d in got] == list(range(1, 1004))
        assert (writer.sent, writer.last_seq) == (1003, 1003)
        batches = batched_records(
            [d for d in counted.datagrams() if HEADER.unpack_from(d)[3] & Flags.BATCH]
        )
        assert all(sum(RECORD.size + len(r[2]) for r in b) <= LIMIT for b in batches)
        assert [r[0] for b in batches for r in b] == [*range(1, 1002), 1003]
    finally:
        counted.close()


def test_send_all_of_more_than_a_batch_splits_where_one_send_each_would(domain_id: int) -> None:
    # messages of mixed sizes, several batches' worth, after one that waits: send_all fills
    # each batch as far as one send() each would, and a flush sends the rest at once
    sizes = [900 + (n * 37) % 700 for n in range(60)]
    splits = []
    for one_by_one in (True, False):
        counted = Counted(domain_id, delay_s=60.0)
        try:
            writer = counted.bus.writer
            writer.send(payload_of(3000, seed=1))
            payloads = [payload_of(size, seed=n) for n, size in enumerate(sizes)]
            if one_by_one:
                for payload in payloads:
                    writer.send(payload)
                writer.flush()
            else:
                writer.send_all(payloads, flush=True)
            got = counted.bus.collector.wait_count(61, timeout=20.0)
            assert [bytes(d.payload) for d in got] == [payload_of(3000, seed=1), *payloads]
            assert [d.seq for d in got] == list(range(1, 62))
            batches = batched_records(counted.datagrams())
            assert all(sum(RECORD.size + len(r[2]) for r in b) <= LIMIT for b in batches)
            splits.append([[r[0] for r in b] for b in batches])
        finally:
            counted.close()
    assert splits[0] == splits[1]
    assert len(splits[0]) >= 4


def test_send_all_with_flush_sends_at_once_what_fits_in_one_datagram(domain_id: int) -> None:
    # the flusher would wait a minute: with flush=True the batch goes out in the same call
    counted = Counted(domain_id, delay_s=60.0)
    try:
        writer = counted.bus.writer
        writer.send(b"first")  # waits in the batch: the others join it
        payloads = [payload_of(64 + n, seed=n) for n in range(20)]
        writer.send_all(payloads, flush=True)
        got = counted.bus.collector.wait_count(21, timeout=20.0)
        assert [bytes(d.payload) for d in got] == [b"first", *payloads]
        assert [d.seq for d in got] == list(range(1, 22))
        writer.send_all([payload_of(200_000, seed=9), b"after"], flush=True)  # too big: sends
        got = counted.bus.collector.wait_count(23, timeout=20.0)
        assert [bytes(d.payload) for d in got[21:]] == [payload_of(200_000, seed=9), b"after"]
        writer.send_all([b"x", b"y"], flush=True)  # nothing pending: these alone, at once
        got = counted.bus.collector.wait_count(25, timeout=20.0)
        assert [(bytes(d.payload), d.seq) for d in got[23:]] == [(b"x", 24), (b"y", 25)]
        batches = batched_records(
            [d for d in counted.datagrams() if HEADER.unpack_from(d)[3] & Flags.BATCH]
        )
        assert [[r[0] for r in b] for b in batches] == [list(range(1, 22)), [23], [24, 25]]
        assert (writer.sent, writer.last_seq) == (25, 25)
    finally:
        counted.close()


def test_gaps_inside_batches_are_counted_as_lost(counted: Counted) -> None:
    for seq in (1, 2, 5, 6, 9):
        counted.bus.writer.send(b"m", seq=seq)
    counted.bus.collector.wait_count(5)
    assert counted.bus.reader.lost() == 4
    assert counted.bus.reader.received() == 5


def test_a_malformed_batch_is_counted_and_the_next_one_still_arrives(counted: Counted) -> None:
    records = RECORD.pack(1, 5, 1000) + b"short"  # claims 1000 bytes, carries 5
    head = HEADER.pack(
        MAGIC, VERSION, Kind.DATA, Flags.BATCH, 1, SENDER, 1, topic_hash(TOPIC), 0, 0,
        ENDPOINT, len(records), time.time_ns(),  # fresh: only the records are wrong
    )  # fmt: skip
    counted.bus.tx.send(counted.bus.writer.channel, [head + records])
    counted.bus.writer.send(b"fine")
    got = counted.bus.collector.wait_count(1, timeout=10.0)
    assert [bytes(d.payload) for d in got] == [b"fine"]
    assert counted.bus.reader.reassembler.malformed == 1


def test_closing_the_flusher_sends_what_is_pending(domain_id: int) -> None:
    counted = Counted(domain_id, delay_s=60.0)  # the timer would never fire in this test
    try:
        counted.bus.writer.send(b"pending")
        time.sleep(0.2)
        assert counted.bus.collector.snapshot() == []
        counted.flusher.close()
        got = counted.bus.collector.wait_count(1, timeout=10.0)
        assert [bytes(d.payload) for d in got] == [b"pending"]
    finally:
        counted.close()


def test_after_the_flusher_closed_a_small_message_goes_out_at_once(domain_id: int) -> None:
    counted = Counted(domain_id, delay_s=60.0)
    try:
        counted.flusher.close()
        counted.bus.writer.send(b"late")
        got = counted.bus.collector.wait_count(1, timeout=10.0)
        assert [bytes(d.payload) for d in got] == [b"late"]
    finally:
        counted.close()


def test_send_all_beside_sends_on_another_thread_never_repeats_a_number(domain_id: int) -> None:
    # send_all reserves its numbers at once: a send() on another thread in between (the sim's
    # flush beside a service's answer) must not take one of them
    import sys
    import threading

    counted = Counted(domain_id, delay_s=0.005)
    try:
        writer = counted.bus.writer

        def sender() -> None:
            for _ in range(3000):
                writer.send(b"x")

        interval = sys.getswitchinterval()
        sys.setswitchinterval(1e-6)  # threads switch between any two bytecodes, nearly
        try:
            thread = threading.Thread(target=sender)
            thread.start()
            while thread.is_alive():
                writer.send_all([b"a", b"b", b"c"])
            thread.join()
        finally:
            sys.setswitchinterval(interval)
        counted.flusher.flush()
        numbers = [r[0] for b in batched_records(counted.datagrams()) for r in b]
        assert len(numbers) == writer.sent
        assert sorted(numbers) == list(range(1, writer.sent + 1))  # each number once
    finally:
        counted.close()
