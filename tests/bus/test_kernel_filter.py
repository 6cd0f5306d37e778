"""The kernel drops datagrams of topics a receiver does not want, before they wake it.

A receiver's channel sockets carry a socket filter made from its reader's wanted topics: a
busy topic sharing the channel of a quiet one never reaches the quiet one's process (its
reader counts nothing unwanted), while foreign datagrams still do (the reader counts them),
and the filter follows the reader's wanted set and ``want_all`` as they change.
"""

from __future__ import annotations

import contextlib
import socket
import time
from typing import TYPE_CHECKING

from rosl.bus import kernel_filter
from rosl.bus.header import HEADER_SIZE, topic_hash
from rosl.bus.multicast import Addressing, MulticastReceiver, MulticastTransport
from rosl.bus.wire import Writer
from tests.bus.helpers import same_channel_name

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.bus.wire import Delivery

BOUND = 10.0  # seconds: only a broken receiver takes this long
TYPE = "std_msgs/msg/String"


@contextlib.contextmanager
def quiet_and_busy(domain_id: int) -> Iterator[tuple[MulticastReceiver, Writer, Writer, Writer]]:
    """A receiver wanting the quiet topic; writers of it and of two busy ones on its channel."""
    transport = MulticastTransport(Addressing(domain_id))
    try:
        quiet = Writer(transport, 0xF00, 1, "/kf/quiet", TYPE)
        busy = Writer(transport, 0xF00, 2, same_channel_name("/kf/quiet", "/kf/busy"), TYPE)
        third = Writer(transport, 0xF00, 3, same_channel_name("/kf/quiet", "/kf/third"), TYPE)
        receiver = transport.receiver()
        receiver.reader.wanted.add(quiet.topic)
        receiver.join(quiet.channel)
        yield receiver, quiet, busy, third
    finally:
        transport.close()


def until_marker(receiver: MulticastReceiver, marker: bytes) -> list[Delivery]:
    """Poll until ``marker`` arrives (bounded): everything sent before it has been handled."""
    got: list[Delivery] = []
    deadline = time.monotonic() + BOUND
    while not any(bytes(d.payload) == marker for d in got):
        assert time.monotonic() < deadline, "the marker never arrived"
        receiver.poll(0.05, got)
    return got


def test_a_busy_topic_on_the_channel_never_reaches_the_reader(domain_id: int) -> None:
    with quiet_and_busy(domain_id) as (receiver, quiet, busy, _):
        for i in range(200):
            busy.send(b"busy %d" % i)
        busy.send(bytes(40_000))  # fragments too
        quiet.send(b"marker")
        got = until_marker(receiver, b"marker")
        assert [bytes(d.payload) for d in got] == [b"marker"]
        assert receiver.reader.unwanted == 0  # the kernel dropped them: no read, no parse
        assert receiver.reader.reassembler.pending == 0


def test_foreign_datagrams_still_come_in_and_are_counted(domain_id: int) -> None:
    with quiet_and_busy(domain_id) as (receiver, quiet, _, _):
        sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
        sender.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
        where = Addressing(domain_id)
        with sender:
            sender.sendto(b"not rosl at all" * 4, (where.group(quiet.channel), where.port))
            sender.sendto(b"RL", (where.group(quiet.channel), where.port))  # shorter than a header
        quiet.send(b"marker")
        until_marker(receiver, b"marker")
        assert receiver.reader.foreign == 2


def test_the_filter_follows_the_wanted_topics(domain_id: int) -> None:
    with quiet_and_busy(domain_id) as (receiver, quiet, busy, third):
        receiver.reader.wanted.add(busy.topic)  # seen at the next poll
        receiver.poll(0.0, [])
        busy.send(b"now wanted")
        third.send(b"still not")
        quiet.send(b"marker 1")
        got = until_marker(receiver, b"marker 1")
        assert sorted(bytes(d.payload) for d in got) == [b"marker 1", b"now wanted"]

        receiver.reader.want_all = True  # a recorder: everything
        receiver.poll(0.0, [])
        third.send(b"everything")
        quiet.send(b"marker 2")
        got = until_marker(receiver, b"marker 2")
        assert sorted(bytes(d.payload) for d in got) == [b"everything", b"marker 2"]

        receiver.reader.want_all = False
        receiver.reader.wanted.discard(busy.topic)
        receiver.poll(0.0, [])
        busy.send(b"dropped again")
        quiet.send(b"marker 3")
        got = until_marker(receiver, b"marker 3")
        assert [bytes(d.payload) for d in got] == [b"marker 3"]
        assert receiver.reader.unwanted == 0


def test_a_new_channel_gets_its_filter_at_join(domain_id: int) -> None:
    with quiet_and_busy(domain_id) as (receiver, quiet, _, _):
        transport = MulticastTransport(Addressing(domain_id))
        try:
            other = Writer(transport, 0xF01, 1, "/kf/elsewhere", TYPE)
            assert other.channel != quiet.channel
            stranger = Writer(
                transport, 0xF01, 2, same_channel_name("/kf/elsewhere", "/kf/stranger"), TYPE
            )
            receiver.reader.wanted.add(other.topic)
            receiver.join(other.channel)
            stranger.send(b"stranger")
            other.send(b"marker")
            got = until_marker(receiver, b"marker")
        finally:
            transport.close()
        assert [bytes(d.payload) for d in got] == [b"marker"]
        assert receiver.reader.unwanted == 0


def test_the_program_keeps_exactly_the_wanted_hashes() -> None:
    """The filter, run by the kernel on a plain UDP socket pair (no multicast involved)."""
    wanted = {topic_hash(f"/kf/p{i}") for i in range(40)}
    unwanted = [topic_hash(f"/kf/q{i}") for i in range(40)]
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    with rx, tx:
        rx.bind(("127.0.0.1", 0))
        rx.settimeout(BOUND)
        assert kernel_filter.attach(rx, wanted)
        for value in [*unwanted, *sorted(wanted)]:
            head = bytearray(HEADER_SIZE)
            head[0:2] = b"RL"
            head[20:28] = value.to_bytes(8, "little")
            tx.sendto(bytes(head), rx.getsockname())
        tx.sendto(b"end", rx.getsockname())  # foreign: let through
        seen = []
        while (data := rx.recv(100)) != b"end":
            seen.append(int.from_bytes(data[20:28], "little"))
        assert seen == sorted(wanted)

        # too many for one filter here: none at all (not the one before, which would drop
        # what was wanted since)
        assert not kernel_filter.attach(rx, set(range(kernel_filter.most_hashes() + 1)))
        tx.sendto(
            bytes(head[:20]) + unwanted[0].to_bytes(8, "little") + bytes(20), rx.getsockname()
        )
        assert int.from_bytes(rx.recv(100)[20:28], "little") == unwanted[0]  # no filter now


def test_a_channel_wanting_more_than_a_filter_holds_lets_everything_in(domain_id: int) -> None:
    # the old, smaller filter must not stay: it would drop what was wanted since (review)
    with quiet_and_busy(domain_id) as (receiver, quiet, busy, _):
        first = [(quiet.channel - 1) + 64 * k for k in range(1, kernel_filter.most_hashes())]
        receiver.reader.wanted.update(first)  # with the quiet topic: exactly as many as fit
        receiver.poll(0.0, [])
        busy.send(b"dropped")
        quiet.send(b"marker 1")
        assert [bytes(d.payload) for d in until_marker(receiver, b"marker 1")] == [b"marker 1"]

        receiver.reader.wanted.update([first[-1] + 64, busy.topic])  # one filter too many
        receiver.poll(0.0, [])
        busy.send(b"now wanted")
        quiet.send(b"marker 2")
        got = until_marker(receiver, b"marker 2")
        assert sorted(bytes(d.payload) for d in got) == [b"marker 2", b"now wanted"]
