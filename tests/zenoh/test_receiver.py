"""The Zenoh transport's receivers: wake-ups, close, and bursts through the short publish way."""

from __future__ import annotations

import contextlib
import threading
import time
from typing import TYPE_CHECKING

import pytest

from rosl.bus.header import topic_hash
from rosl.bus.wire import Writer
from rosl.bus.zenoh_wire import ATTACHMENT, gid_of

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.bus.wire import Delivery
    from rosl.bus.zenoh_transport import ZenohTransport
    from tests.zenoh.conftest import Router

BOUND = 30.0  # seconds: generous, only a broken receiver takes this long
TYPE = "std_msgs/msg/String"


@pytest.fixture
def transport(router: Router, domain_id: int) -> Iterator[ZenohTransport]:
    from rosl.bus.zenoh_transport import ZenohTransport

    with contextlib.closing(ZenohTransport(domain_id)) as made:
        yield made


def _string(text: str) -> bytes:
    data = text.encode() + b"\x00"
    return b"\x00\x01\x00\x00" + len(data).to_bytes(4, "little") + data


def _returns(call: object) -> threading.Event:
    """Run ``call`` in a thread; the event is set once it returned."""
    done = threading.Event()

    def run() -> None:
        call()  # type: ignore[operator]
        done.set()

    threading.Thread(target=run, daemon=True).start()
    return done


def test_a_nested_poll_leaves_the_wake_up_to_the_next_full_poll(
    transport: ZenohTransport,
) -> None:
    receiver = transport.receiver()
    receiver.join(1)
    receiver.wake()
    got: list[Delivery] = []
    assert receiver.poll(0.1, got, channel=1) == 0  # waits its timeout, keeps the wake-up
    assert got == []
    assert _returns(lambda: receiver.poll(None, [])).wait(BOUND)  # with no timeout: woken
    # taken: the next full poll waits again
    assert not _returns(lambda: receiver.poll(0.3, [])).wait(0.1)


def test_close_ends_a_blocked_poll_and_later_polls_read_nothing(
    transport: ZenohTransport,
) -> None:
    receiver = transport.receiver()
    receiver.join(1)
    returned = _returns(lambda: receiver.poll(None, []))
    assert not returned.wait(0.2)
    receiver.close()
    assert returned.wait(BOUND)
    got: list[Delivery] = []
    assert receiver.poll(0.05, got) == 0
    assert got == []
    receiver.close()


def test_a_burst_published_the_short_way_arrives_whole_in_order_and_counted(
    transport: ZenohTransport,
) -> None:
    name, sender, endpoint = "/burst", 0xABC1, 9
    writer = Writer(transport, sender, endpoint, name, TYPE)
    receiver = transport.receiver()
    receiver.reader.wanted.add(topic_hash(name))
    receiver.join(writer.channel)
    key = transport.route(writer.topic, name, TYPE, False).key
    transport.subscribe(key)
    time.sleep(0.2)  # the subscriber is declared in the session; puts from now on reach it
    total = 500
    for number in range(total):
        writer.send(_string(f"message {number}"))
    got: list[Delivery] = []
    deadline = time.monotonic() + BOUND
    while len(got) < total and time.monotonic() < deadline:
        receiver.poll(0.1, got)
    assert [bytes(d.payload) for d in got] == [_string(f"message {n}") for n in range(total)]
    assert [d.seq for d in got] == list(range(1, total + 1))
    # the sender and endpoint come back out of the GID's first ten bytes
    provisional = gid_of(f"{transport.zid}/{sender:016x}/{endpoint}")
    assert {(d.sender, d.endpoint) for d in got} == {
        (int.from_bytes(provisional[:8], "little") | 1, int.from_bytes(provisional[8:10], "little"))
    }
    stats = receiver.reader.streams[(got[0].sender, got[0].endpoint)]
    assert (stats.received, stats.lost) == (total, 0)


def test_a_sample_with_a_malformed_attachment_is_dropped(transport: ZenohTransport) -> None:
    name = "/malformed"
    writer = Writer(transport, 0xABC3, 4, name, TYPE)
    receiver = transport.receiver()
    receiver.reader.wanted.add(topic_hash(name))
    receiver.join(writer.channel)
    key = transport.route(writer.topic, name, TYPE, False).key
    transport.subscribe(key)
    time.sleep(0.2)
    good = ATTACHMENT.pack(7, time.time_ns(), 16, bytes(16))
    publisher = transport.session.declare_publisher(key)
    publisher.put(_string("short"), attachment=good[:20])
    publisher.put(_string("gid length 15"), attachment=good[:16] + b"\x0f" + good[17:])
    publisher.put(_string("none"))
    publisher.put(_string("fine"), attachment=good)
    got: list[Delivery] = []
    deadline = time.monotonic() + BOUND
    while not got and time.monotonic() < deadline:
        receiver.poll(0.1, got)
    receiver.poll(0.3, got)
    assert [bytes(d.payload) for d in got] == [_string("fine")]
    assert got[0].seq == 7


def test_a_raw_subscription_gets_each_message_as_the_bytes_that_were_sent(
    router: Router, ros: object
) -> None:
    from std_msgs.msg import String

    import rosl
    from tests.conftest import wait_until

    node = rosl.create_node("raw_listener")
    heard: list[object] = []
    node.create_subscription(String, "/raw", heard.append, 10, raw=True)
    publisher = node.create_publisher(String, "/raw", 10)
    big = "x" * 200_000  # a large message: the received bytes object is passed on

    def exchanged() -> bool:
        publisher.publish(String(data=big))
        rosl.spin_once(node, timeout_sec=0.1)
        return bool(heard)

    assert wait_until(exchanged, BOUND)
    assert type(heard[0]) is bytes
    assert heard[0] == _string(big)
