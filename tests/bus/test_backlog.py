"""The multicast receiver reads no more of a channel than its queues hold, until it is behind.

A poll given ``limits`` takes at most that many datagrams of a channel; the rest wait in the
socket's buffer. A socket that stays behind longer than the receiver's backlog bound is
drained whole (up to the drain limit) once, and the bound starts again.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from rosl.bus.multicast import Addressing, MulticastTransport
from rosl.bus.wire import Writer

if TYPE_CHECKING:
    from rosl.bus.wire import Delivery

BOUND = 10.0  # seconds: only a broken receiver takes this long
BURST = 200


def polls(domain_id: int, backlog_ns: int, limit: int) -> tuple[list[int], list[Delivery]]:
    """Send a burst, then poll with ``limit``: how many each poll took, and what arrived."""
    transport = MulticastTransport(Addressing(domain_id))
    try:
        out = Writer(transport, 0xF00, 3, "/backlog", "std_msgs/msg/String")
        receiver = transport.receiver()
        receiver.backlog_ns = backlog_ns
        receiver.reader.wanted.add(out.topic)
        receiver.join(out.channel)
        for i in range(BURST):
            out.send(b"message %d" % i)
        got: list[Delivery] = []
        taken = []
        deadline = time.monotonic() + BOUND
        while len(got) < BURST and time.monotonic() < deadline:
            before = len(got)
            receiver.poll(0.05, got, None, {out.channel: limit})
            if len(got) > before:
                taken.append(len(got) - before)
        return taken, got
    finally:
        transport.close()


def test_a_poll_takes_no_more_than_the_limit_and_the_rest_waits_in_the_socket(domain_id):
    taken, got = polls(domain_id, backlog_ns=60_000_000_000, limit=10)

    assert [d.seq for d in got] == list(range(1, BURST + 1))  # nothing lost, in order
    assert max(taken) <= 10
    assert len(taken) >= BURST // 10


def test_a_socket_behind_longer_than_the_bound_is_drained_whole_once(domain_id):
    taken, got = polls(domain_id, backlog_ns=0, limit=10)

    assert [d.seq for d in got] == list(range(1, BURST + 1))
    assert taken[0] <= 10  # the first poll saw no backlog yet
    assert max(taken) > 10  # then it was behind: a whole drain
