"""The transport seam's contract, held by every transport: multicast and in-process."""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING

import pytest

from rosl.bus.errors import BusError
from rosl.bus.header import topic_hash
from rosl.bus.inprocess import InProcessTransport
from rosl.bus.multicast import Addressing, MulticastTransport
from rosl.bus.transport import CHANNELS, channel_of, open_transport
from rosl.bus.wire import Writer

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.bus.transport import Receiver, Transport
    from rosl.bus.wire import Delivery

TRANSPORTS = ["multicast", "inprocess"]
BOUND = 10.0  # seconds: generous, only a broken transport takes this long


@pytest.fixture(params=TRANSPORTS)
def transport(request: pytest.FixtureRequest, domain_id: int) -> Iterator[Transport]:
    made: Transport = (
        MulticastTransport(Addressing(domain_id))
        if request.param == "multicast"
        else InProcessTransport(domain_id)
    )
    try:
        yield made
    finally:
        made.close()


def collect(receiver: Receiver, count: int, channel: int | None = None) -> list[Delivery]:
    """Poll until ``count`` deliveries arrived (bounded)."""
    got: list[Delivery] = []
    deadline = time.monotonic() + BOUND
    while len(got) < count and time.monotonic() < deadline:
        receiver.poll(0.05, got, channel)
    return got


def endpoint_of(topic: str) -> int:
    """One endpoint number per topic, as a process numbers its endpoints."""
    return 7 + sum(topic.encode())


def writer(transport: Transport, topic: str = "/seam", sender: int = 0xABC) -> Writer:
    return Writer(transport, sender, endpoint_of(topic), topic, "std_msgs/msg/String")


def test_a_joined_receiver_gets_whole_deliveries_with_their_sender_sequence_and_stamps(
    transport: Transport,
) -> None:
    out = writer(transport)
    receiver = transport.receiver()
    receiver.reader.wanted.add(out.topic)
    receiver.join(out.channel)
    before = time.time_ns()
    for i in range(5):
        out.send(b"message %d" % i)
    got = collect(receiver, 5)
    assert [bytes(d.payload) for d in got] == [b"message %d" % i for i in range(5)]
    assert [d.seq for d in got] == [1, 2, 3, 4, 5]
    assert {(d.sender, d.endpoint, d.topic) for d in got} == {
        (0xABC, endpoint_of("/seam"), topic_hash("/seam"))
    }
    assert all(before <= d.stamp <= d.received for d in got)
    assert receiver.reader.lost() == 0


def test_a_message_larger_than_a_datagram_arrives_whole(transport: Transport) -> None:
    out = writer(transport)
    receiver = transport.receiver()
    receiver.reader.wanted.add(out.topic)
    receiver.join(out.channel)
    big = bytes(range(256)) * (3 * transport.max_datagram // 256 + 7)
    out.send(big)
    (got,) = collect(receiver, 1)
    assert bytes(got.payload) == big


def test_every_receiver_of_a_channel_gets_each_datagram_and_others_none(
    transport: Transport,
) -> None:
    out = writer(transport)
    first, second, elsewhere = (transport.receiver() for _ in range(3))
    for receiver in (first, second, elsewhere):
        receiver.reader.want_all = True
    first.join(out.channel)
    second.join(out.channel)
    elsewhere.join(out.channel % CHANNELS + 1)  # another data channel
    out.send(b"to all")
    assert [bytes(d.payload) for d in collect(first, 1)] == [b"to all"]
    assert [bytes(d.payload) for d in collect(second, 1)] == [b"to all"]
    stray: list[Delivery] = []
    elsewhere.poll(0.2, stray)
    assert stray == []


def test_after_leave_a_channel_delivers_nothing(transport: Transport) -> None:
    out = writer(transport)
    receiver = transport.receiver()
    receiver.reader.want_all = True
    receiver.join(out.channel)
    out.send(b"before")
    assert len(collect(receiver, 1)) == 1
    receiver.leave(out.channel)
    out.send(b"after")
    got: list[Delivery] = []
    receiver.poll(0.2, got)
    assert got == []


def test_a_channel_joined_between_polls_is_watched_by_the_next_poll(transport: Transport) -> None:
    first, second = writer(transport, "/seam"), writer(transport, "/other_seam")
    assert first.channel != second.channel
    receiver = transport.receiver()
    receiver.reader.want_all = True
    receiver.join(first.channel)
    first.send(b"on the first")
    assert [bytes(d.payload) for d in collect(receiver, 1)] == [b"on the first"]
    receiver.join(second.channel)  # after polls that watched only the first channel
    second.send(b"on the second")
    assert [bytes(d.payload) for d in collect(receiver, 1)] == [b"on the second"]
    receiver.leave(first.channel)
    first.send(b"left")
    second.send(b"still joined")
    assert [bytes(d.payload) for d in collect(receiver, 1)] == [b"still joined"]


def test_wake_ends_a_poll_that_waits_without_a_timeout(transport: Transport) -> None:
    receiver = transport.receiver()
    receiver.join(1)
    returned = threading.Event()

    def wait_forever() -> None:
        receiver.poll(None, [])
        returned.set()

    thread = threading.Thread(target=wait_forever, daemon=True)
    thread.start()
    assert not returned.wait(0.2)  # nothing arrived: still waiting
    receiver.wake()
    assert returned.wait(BOUND)


def test_a_poll_of_one_channel_reads_only_it_and_leaves_the_wake_up_for_the_spinner(
    transport: Transport,
) -> None:
    a, b = writer(transport, "/a"), writer(transport, "/b")
    assert a.channel != b.channel
    receiver = transport.receiver()
    receiver.reader.want_all = True
    receiver.join(a.channel)
    receiver.join(b.channel)
    b.send(b"on b")
    receiver.wake()  # meant for the spinning thread
    only_b = collect(receiver, 1, channel=b.channel)
    assert [bytes(d.payload) for d in only_b] == [b"on b"]
    # the nested poll left the wake-up: a full poll with nothing to read ends at once
    woken = threading.Event()
    thread = threading.Thread(target=lambda: (receiver.poll(None, []), woken.set()), daemon=True)
    thread.start()
    assert woken.wait(BOUND)
    a.send(b"on a")
    nothing: list[Delivery] = []
    receiver.poll(0.2, nothing, channel=b.channel)
    assert nothing == []
    assert [bytes(d.payload) for d in collect(receiver, 1)] == [b"on a"]


def test_a_closed_receiver_polls_nothing_and_close_is_idempotent(transport: Transport) -> None:
    out = writer(transport)
    receiver = transport.receiver()
    receiver.reader.want_all = True
    receiver.join(out.channel)
    receiver.close()
    out.send(b"late")
    got: list[Delivery] = []
    assert receiver.poll(0.05, got) == 0
    assert got == []
    receiver.close()


def test_the_transport_says_where_its_traffic_goes(transport: Transport, domain_id: int) -> None:
    text = transport.describe()
    assert str(domain_id) in text
    assert transport.name
    assert transport.fix_hint


def test_rosl_transport_picks_the_transport(
    monkeypatch: pytest.MonkeyPatch, domain_id: int
) -> None:
    monkeypatch.setenv("ROSL_TRANSPORT", "inprocess")
    chosen = open_transport(domain_id)
    assert isinstance(chosen, InProcessTransport)
    chosen.close()
    monkeypatch.delenv("ROSL_TRANSPORT")
    chosen = open_transport(domain_id)
    assert isinstance(chosen, MulticastTransport)
    chosen.close()


def test_an_unknown_transport_is_one_line_naming_the_choices(
    monkeypatch: pytest.MonkeyPatch, domain_id: int
) -> None:
    monkeypatch.setenv("ROSL_TRANSPORT", "carrier-pigeon")
    with pytest.raises(BusError) as caught:
        open_transport(domain_id)
    message = str(caught.value)
    assert "\n" not in message
    assert "'carrier-pigeon'" in message
    assert "multicast" in message
    assert "inprocess" in message


def test_in_process_domains_never_hear_each_other(domain_id: int) -> None:
    one, other = InProcessTransport(domain_id), InProcessTransport(domain_id + 1000)
    try:
        receiver = other.receiver()
        receiver.reader.want_all = True
        receiver.join(channel_of(topic_hash("/seam")))
        writer(one).send(b"domain one")
        got: list[Delivery] = []
        receiver.poll(0.2, got)
        assert got == []
    finally:
        one.close()
        other.close()
