"""Coalescing writers: many small messages per datagram, unpacked into ordinary deliveries."""

from __future__ import annotations

import select
import time
from typing import TYPE_CHECKING

import pytest

from rosl.bus.coalesce import RECORD, Flusher
from rosl.bus.header import HEADER, MAGIC, VERSION, Flags, Kind, topic_hash
from rosl.bus.multicast import Addressing
from rosl.bus.transport import MulticastTransport
from tests.bus.test_wire import ENDPOINT, SENDER, TOPIC, Bus, payload_of

if TYPE_CHECKING:
    import socket
    from collections.abc import Iterator


class Counted:
    """A bus whose writer coalesces, plus a second socket on the channel counting datagrams."""

    def __init__(self, domain: int, delay_s: float = 0.001, limit: int = 16384) -> None:
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


def test_small_messages_share_datagrams_and_arrive_whole_in_order(counted: Counted) -> None:
    payloads = [payload_of(64, seed=n) for n in range(1000)]
    stamps = []
    for n, payload in enumerate(payloads):
        stamps.append(1_000_000 + n)
        counted.bus.writer.send(payload, stamp=stamps[-1])

    got = counted.bus.collector.wait_count(1000)
    assert [bytes(d.payload) for d in got] == payloads
    assert [d.seq for d in got] == list(range(1, 1001))
    assert [d.stamp for d in got] == stamps
    assert {(d.kind, d.sender, d.endpoint, d.flags) for d in got} == {
        (Kind.DATA, SENDER, ENDPOINT, 0)
    }
    assert counted.bus.reader.lost() == 0
    datagrams = counted.datagrams()
    assert all(d[:2] == MAGIC and HEADER.unpack_from(d)[3] & Flags.BATCH for d in datagrams)
    per_datagram = (16384 - 0) // (RECORD.size + 64)
    assert len(datagrams) <= 1000 // per_datagram + 2  # not one datagram a message


def test_a_lone_message_goes_out_within_the_delay_without_further_sends(
    counted: Counted,
) -> None:
    sent = time.monotonic()
    counted.bus.writer.send(b"alone")
    got = counted.bus.collector.wait_count(1, timeout=2.0)
    assert [bytes(d.payload) for d in got] == [b"alone"]
    assert time.monotonic() - sent < 1.0


def test_a_big_message_after_small_ones_keeps_its_place(counted: Counted) -> None:
    big = payload_of(200_000, seed=9)
    counted.bus.writer.send(b"one")
    counted.bus.writer.send(b"two")
    counted.bus.writer.send(big)  # fragmented: the batch must go first
    counted.bus.writer.send(b"three")
    got = counted.bus.collector.wait_count(4, timeout=5.0)
    assert [bytes(d.payload) for d in got] == [b"one", b"two", big, b"three"]
    assert [d.seq for d in got] == [1, 2, 3, 4]


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
        ENDPOINT, len(records), 5,
    )  # fmt: skip
    counted.bus.tx.send(counted.bus.writer.channel, [head + records])
    counted.bus.writer.send(b"fine")
    got = counted.bus.collector.wait_count(1, timeout=2.0)
    assert [bytes(d.payload) for d in got] == [b"fine"]
    assert counted.bus.reader.reassembler.malformed == 1


def test_closing_the_flusher_sends_what_is_pending(domain_id: int) -> None:
    counted = Counted(domain_id, delay_s=60.0)  # the timer would never fire in this test
    try:
        counted.bus.writer.send(b"pending")
        time.sleep(0.2)
        assert counted.bus.collector.snapshot() == []
        counted.flusher.close()
        got = counted.bus.collector.wait_count(1, timeout=2.0)
        assert [bytes(d.payload) for d in got] == [b"pending"]
    finally:
        counted.close()


def test_after_the_flusher_closed_a_small_message_goes_out_at_once(domain_id: int) -> None:
    counted = Counted(domain_id, delay_s=60.0)
    try:
        counted.flusher.close()
        counted.bus.writer.send(b"late")
        got = counted.bus.collector.wait_count(1, timeout=2.0)
        assert [bytes(d.payload) for d in got] == [b"late"]
    finally:
        counted.close()
