"""The recorder's intake thread: it queues what arrives, stops taking while the queue is over
its bound (what comes meanwhile waits in the socket), and ends with its participant.

A real participant receives on the test's domain; a second one publishes to it.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from rosl.bag import inbox
from rosl.bus.header import topic_hash
from tests.conftest import wait_until

if TYPE_CHECKING:
    import pytest

    from rosl.bus.wire import Delivery

TOPIC = "/intake_test"


class _Ignore:
    def deliver(self, delivery: Delivery) -> None:
        """Unused: the intake reads through ``poll(sink=...)``."""


def test_the_intake_stops_taking_over_its_bound_and_takes_the_rest_once_drained(
    domain_id: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rosl.bus.wire import Writer
    from rosl.node.participant import Participant

    # one held message (600 bytes + HELD_OVERHEAD) is under the bound, two are over it: the
    # intake takes at least two, however its polls split the burst (one at a time under load)
    monkeypatch.setattr(inbox, "INBOX_BYTES", 700 + inbox.HELD_OVERHEAD)
    receiver, sender = Participant(domain_id), Participant(domain_id)
    intake = None
    try:
        receiver.listen(topic_hash(TOPIC), _Ignore())
        writer = Writer(
            sender.transport, sender.sender, sender.next_endpoint(), TOPIC, "std_msgs/msg/String"
        )
        intake = running = inbox.Intake(receiver)
        taken: list[Delivery] = []

        def send(count: int, first: int) -> None:
            for n in range(first, first + count):
                writer.send(n.to_bytes(4, "little") + bytes(600))

        send(3, 0)  # 3 x 600 bytes: over the bound once the second is queued
        assert wait_until(lambda: running.queued >= 2, timeout=15.0)
        time.sleep(0.2)  # the thread sees it is over its bound
        held = intake.queued
        send(5, 3)
        time.sleep(0.3)
        assert intake.queued == held  # nothing more is taken while over the bound
        taken += intake.take()
        # the socket kept them: once drained, the intake takes them
        assert wait_until(lambda: len(taken) + running.queued == 8, timeout=15.0)
        while len(taken) < 8:
            taken += intake.take()
            time.sleep(0.01)
        numbers = [int.from_bytes(bytes(d.payload)[:4], "little") for d in taken]
        assert numbers == list(range(8))
        receiver.close()
        intake.stop()  # ends with its participant (joined: no thread left polling)
    finally:
        if intake is not None:
            intake.stop()
        receiver.close()
        sender.close()
