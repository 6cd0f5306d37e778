"""The recorder's hold of messages on topics it cannot name yet is bounded in bytes and time.

Unit tests drive the hold (``inbox.Pending``) with hand-made deliveries: the oldest go
first, each buffer is counted once, a message bigger than the whole hold is refused, and the
per-topic books only name topics that have messages held.

The bus test runs a real :class:`Recorder` in this process on the test's domain and floods it,
through rosl's own bus API (a :class:`rosl.bus.wire.Writer` on ``open_transport``), with
30 KB messages on random topics nobody announces, three times what the hold may keep. In the
last part of the flood it also sends a few messages on ``/late``, a topic a real node announces
only after the flood. The hold must stay within ``PENDING_BYTES`` after every message, count
what it drops, keep the newest messages (``/late``'s), release everything else within
``PENDING_LIMIT_S`` with no further traffic, and the bag must hold ``/late``'s early messages
followed by the node's.
"""

from __future__ import annotations

import random
import time
import uuid
from typing import TYPE_CHECKING, Any

from rosl.bag import recorder as recorder_module
from rosl.bag.inbox import HELD_OVERHEAD, Pending
from rosl.bag.recorder import PENDING_BYTES, PENDING_MAX, Recorder
from rosl.bus.header import Kind, topic_hash, type_hash
from rosl.bus.wire import Delivery
from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path

    import pytest

    from tests.conftest import Processes

STRING = "std_msgs/msg/String"

# --- the hold on its own -------------------------------------------------------------------------


def delivery(topic: str, payload: memoryview | bytearray, seq: int = 1) -> Delivery:
    """A data message on ``topic`` as the bus hands it over."""
    return Delivery(
        int(Kind.DATA), 7, 1, seq, topic_hash(topic), type_hash("fuzz_msgs/msg/Noise"),
        seq, seq, payload,
    )  # fmt: skip


def datagram(size: int) -> memoryview:
    """A message's payload as the bus gives it: a view past the header of its own datagram."""
    return memoryview(bytes(size + 40))[40:]


def keys(hold: Any) -> list[tuple[int, int]]:
    return [(entry.delivery.topic, entry.delivery.type) for entry in hold.held]


def test_the_oldest_held_messages_are_dropped_first_when_the_bytes_run_out() -> None:
    cost = 1040 + HELD_OVERHEAD  # each payload keeps its whole 1040-byte datagram alive
    hold = Pending(max_count=100, max_bytes=4 * cost)
    topics = [f"/t{i}" for i in range(6)]
    dropped = [hold.add(delivery(t, datagram(1000)), now=float(i)) for i, t in enumerate(topics)]
    assert dropped == [0, 0, 0, 0, 1, 1]
    assert [d.delivery.topic for d in hold.held] == [topic_hash(t) for t in topics[2:]]
    assert hold.bytes == 4 * cost
    # the per-topic books name exactly the topics with messages held, with their first hold
    assert set(hold.since) == set(keys(hold)) == set(hold.counts)
    assert sorted(hold.since.values()) == [2.0, 3.0, 4.0, 5.0]

    # a message bigger than the whole hold is refused; nothing else goes, no books grow
    assert hold.add(delivery("/huge", bytearray(4 * cost)), now=9.0) == 1
    assert [d.delivery.topic for d in hold.held] == [topic_hash(t) for t in topics[2:]]
    assert set(hold.since) == set(keys(hold))

    # one message needing room for two drops the two oldest
    assert hold.add(delivery("/big", bytearray(cost + 1)), now=10.0) == 2
    assert [d.delivery.topic for d in hold.held] == [topic_hash(t) for t in (*topics[4:], "/big")]
    assert hold.bytes == 2 * cost + cost + 1 + HELD_OVERHEAD <= hold.max_bytes
    assert set(hold.since) == set(keys(hold)) == set(hold.counts)


def test_the_count_bound_also_drops_the_oldest() -> None:
    hold = Pending(max_count=3, max_bytes=PENDING_BYTES)
    for i in range(5):
        hold.add(delivery("/same", bytearray(10), seq=i), now=float(i))
    assert [d.delivery.seq for d in hold.held] == [2, 3, 4]
    assert hold.counts == {(topic_hash("/same"), type_hash("fuzz_msgs/msg/Noise")): 3}
    assert list(hold.since.values()) == [0.0]  # held without a break since the first


def test_messages_sharing_a_datagram_count_it_once_and_free_it_with_the_last() -> None:
    whole = bytes(60_000)
    view = memoryview(whole)
    hold = Pending(max_count=100, max_bytes=PENDING_BYTES)
    for i in range(10):  # a coalesced datagram: ten records, one buffer
        hold.add(delivery("/batched", view[i * 6000 : (i + 1) * 6000], seq=i), now=0.0)
    assert hold.bytes == len(whole) + 10 * HELD_OVERHEAD
    hold.retry(lambda d: d.seq < 9)  # all but the last are recorded: the buffer stays alive
    assert [d.delivery.seq for d in hold.held] == [9]
    assert hold.bytes == len(whole) + HELD_OVERHEAD
    hold.retry(lambda d: True)
    assert hold.bytes == 0
    assert not hold.held
    assert hold.since == {}
    assert hold.counts == {}
    assert hold.buffers == {}


def test_retry_keeps_the_order_and_expiry_empties_the_books() -> None:
    hold = Pending(max_count=100, max_bytes=PENDING_BYTES)
    for i, topic in enumerate(["/a", "/b", "/a", "/c", "/b"]):
        hold.add(delivery(topic, datagram(100), seq=i), now=float(i))
    hold.retry(lambda d: d.topic == topic_hash("/c"))
    assert [d.delivery.seq for d in hold.held] == [0, 1, 2, 4]
    assert hold.expire(now=3.5, limit=3.0) == 2  # /a, held since 0.0; /b (since 1.0) stays
    assert [d.delivery.seq for d in hold.held] == [1, 4]
    assert set(hold.since) == {(topic_hash("/b"), type_hash("fuzz_msgs/msg/Noise"))}
    assert hold.expire(now=100.0, limit=3.0) == 2
    assert hold.bytes == 0
    assert hold.since == {}
    assert hold.counts == {}


# --- a real recorder flooded on the bus ----------------------------------------------------------

FLOOD = 3000  # messages on random unknown topics
SIZE = 30_000  # bytes each: one datagram
BURST = 20  # sent at once; then the recorder catches up (bounded wait) so the socket keeps up
LATE_FROM = FLOOD - 300  # /late's early messages come among the last 9 MB of the flood
LATE_EVERY = 60
NODE_MESSAGES = ["node 0", "node 1", "node 2"]


class Flood:
    """What the recorder's sink saw of the strangers, checked after every message."""

    def __init__(self, recorder: Recorder, strangers: set[int]) -> None:
        self.recorder = recorder
        self.strangers = strangers
        self.seen = 0  # stranger messages that reached the recorder
        self.late_seen = 0
        self.most = 0  # the most bytes held at any time
        self._sink = recorder._on_delivery

    def sink(self, delivery: Delivery) -> None:
        if delivery.topic in self.strangers:
            self.seen += 1
        elif delivery.topic == topic_hash("/late"):
            self.late_seen += 1
        self._sink(delivery)
        self.check()

    def check(self) -> None:
        held = self.recorder.held_bytes
        pending = self.recorder._pending
        assert held <= PENDING_BYTES, f"{held} bytes held, more than {PENDING_BYTES}"
        assert len(pending) <= PENDING_MAX
        self.most = max(self.most, held)


def step_until(recorder: Recorder, flood: Flood, done: Any, timeout: float) -> bool:
    """Step the recorder until ``done()`` (bounded by ``timeout``)."""
    deadline = time.monotonic() + timeout
    while not done():
        if time.monotonic() > deadline:
            return False
        recorder.step(0.02)
        flood.check()
    return True


def test_a_flood_of_unknown_topics_stays_in_bounds_and_a_late_announced_topic_is_recorded(
    domain_id: int, processes: Processes, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rosl.bus.transport import open_transport
    from rosl.bus.wire import Writer

    lines: list[str] = []
    folder = tmp_path / "flood_bag"
    recorder = Recorder(folder, domain=domain_id, log=lines.append)
    transport = open_transport(domain_id)
    child = None
    try:
        recorder.start()
        # expiry would release the strangers before the bytes run out on a slow machine: the
        # flood checks the byte bound alone, the time bound is checked on its own afterwards
        monkeypatch.setattr(recorder_module, "PENDING_LIMIT_S", 3600.0)
        sender = random.getrandbits(63)
        names = [f"/stranger_{uuid.uuid4().hex}" for _ in range(FLOOD)]
        strangers = {topic_hash(name) for name in names}
        flood = Flood(recorder, strangers)
        monkeypatch.setattr(recorder, "_on_delivery", flood.sink)
        late = Writer(transport, sender, 1, "/late", STRING)
        # as big as the strangers': a hold that refused new messages when full would lose them
        early = [f"early {i} " + "x" * SIZE for i in range(LATE_FROM, FLOOD, LATE_EVERY)]
        payload = random.randbytes(SIZE)
        late_sent = lost = 0  # lost: in transit (tolerated; counted from what arrived)
        for index, name in enumerate(names):
            Writer(transport, sender, 2 + index % 60000, name, "fuzz_msgs/msg/Noise").send(payload)
            sent = index + 1
            if index >= LATE_FROM and (index - LATE_FROM) % LATE_EVERY == 0:
                late.send(support.cdr(STRING, {"data": early[late_sent]}))
                late_sent += 1
            if sent % BURST == 0 or sent == FLOOD:
                caught_up = step_until(
                    recorder,
                    flood,
                    lambda: flood.seen + lost >= sent and flood.late_seen >= late_sent,  # noqa: B023
                    timeout=5.0,
                )
                if not caught_up:
                    lost = sent - flood.seen
        received = flood.seen * len(payload)
        assert received > 1.5 * PENDING_BYTES, (
            f"only {flood.seen} of {FLOOD} flood messages arrived: the bound was not tested"
        )
        assert flood.late_seen == len(early), "an early /late message was lost in transit"
        # the hold filled up to its bound, and everything that did not fit was dropped
        assert flood.most > PENDING_BYTES - 2 * (SIZE + 1024 + HELD_OVERHEAD)
        assert recorder.dropped_unknown > 0
        late_key = (topic_hash("/late"), type_hash(STRING))
        assert recorder._pending.counts.get(late_key) == len(early), "/late's messages went"
        held = len(recorder._pending)
        assert recorder.dropped_unknown == flood.seen + len(early) - held
        assert len(recorder._pending.since) == held - len(early) + 1  # one topic each; /late

        # a real node announces /late and publishes on it: the held messages are recorded too
        child = support.start_publisher(
            processes,
            {"node": "late_talker", "publishers": [{"topic": "/late", "type": STRING}],
             "messages": [(0, {"data": text}) for text in NODE_MESSAGES]},
        )  # fmt: skip

        def exited() -> bool:
            child.pump()
            return child.popen.poll() is not None

        assert step_until(recorder, flood, exited, 60.0), child.both()
        assert child.finish(10.0) == 0, child.both()
        assert late_key not in recorder._pending.since

        # no more traffic: the strangers are released once held for PENDING_LIMIT_S
        strangers_held = sum(1 for e in recorder._pending.held if e.key[0] in strangers)
        assert strangers_held > 0
        dropped = recorder.dropped_unknown
        monkeypatch.setattr(recorder_module, "PENDING_LIMIT_S", 3.0)
        assert step_until(recorder, flood, lambda: len(recorder._pending) == 0, 3.0 + 30.0), (
            f"{len(recorder._pending)} messages still held"
        )
        assert recorder.held_bytes == 0
        assert recorder._pending.since == {}
        assert recorder._pending.counts == {}
        assert recorder.dropped_unknown == dropped + strangers_held
    finally:
        transport.close()
        recorder.close()

    assert f", {recorder.dropped_unknown} of unknown topics dropped" in lines[-1]
    assert support.topic_counts(folder)["/late"] == len(early) + len(NODE_MESSAGES)
    messages = support.by_topic([m for f in support.read_mcap(folder) for m in f.messages])["/late"]
    found = [m.fields["data"] for m in messages]
    assert [text[:12] for text in found] == [text[:12] for text in early + NODE_MESSAGES]
    assert found == early + NODE_MESSAGES
    assert not set(support.topic_counts(folder)) & set(names)
