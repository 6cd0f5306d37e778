"""Lock-step with a simulator: the sim waits until its subscribers have handled each step.

A lock-stepped simulator (``rosl sim --fast``) marks its messages with ``Flags.LOCKSTEP``. A
process that spins an executor remembers, per simulator publisher, the last such message it
handled, and at the end of the executor iteration (after the timers the new ``/clock`` made
due) answers on the hidden topic ``/_lockstep`` with a ``rosl_msgs/msg/LockstepAck``: what it
handled, when its next sim-time timer is due, and the last sequence number of each of its own
publishers. The simulator waits for the answers of every lock-step process subscribed to what
it published in the step (a ``/clock``-only subscriber only when one of its timers is due),
then makes sure their replies (a ``/cmd_vel``) have arrived before it steps again. So a
controller's reply always lands in the same step, whatever the machine's speed, and two runs
with the same inputs give the same messages.

Processes announce that they answer (``lockstep`` in their discovery record) when their first
executor iteration starts; tools that only observe (``rosl bag record``) never answer and are
never waited for. A peer that stops answering is reported by name after a bounded wait; the
simulator then goes on without it (until it answers again) or stops, as configured.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.bus.header import Flags, topic_hash
from rosl.bus.wire import Writer
from rosl.graph.records import SUBSCRIPTION
from rosl.node.errors import NodeError

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.wire import Delivery
    from rosl.node.participant import Participant
    from rosl.node.publisher import Publisher

TOPIC = "/_lockstep"
TYPE = "rosl_msgs/msg/LockstepAck"
CLOCK_HASH = topic_hash("/clock")
_TOPIC_HASH = topic_hash(TOPIC)


class LockstepStall(NodeError):  # noqa: N818 - reads as what happened
    """A lock-step peer did not answer in time and the simulator was told to stop."""


def _newer(seq: int, than: int) -> bool:
    """``seq`` is at or after ``than`` (32-bit sequence numbers wrap)."""
    return ((seq - than) & 0xFFFFFFFF) < 0x80000000


# --- the answering side (every process that spins an executor) -------------------------------


class Answerer:
    """Collects lock-stepped deliveries this process handled and answers once per iteration."""

    def __init__(self, participant: Participant) -> None:
        self.participant = participant
        self.seen: dict[int, dict[int, int]] = {}  # source process -> endpoint -> seq
        self._data = False  # handled a lock-stepped message other than /clock
        self._writer: Writer | None = None
        self._told: dict[int, int] = {}  # source -> next_wakeup last told
        self._baseline: dict[int, dict[int, int]] = {}  # source -> id(writer) -> seq last told
        self._class: Any = None
        self._gone: deque[int] = deque(maxlen=4096)  # simulators that left (forgotten on answer)
        participant.discovery.on_gone.append(self._gone.append)

    def _forget_gone(self) -> None:
        """Stop answering simulators that said goodbye or whose lease ran out."""
        while self._gone:
            source = self._gone.popleft()
            for table in (self.seen, self._told, self._baseline):
                table.pop(source, None)

    def handled(self, delivery: Delivery) -> None:
        """Remember a lock-stepped delivery that a subscription of this process took."""
        source = delivery.sender
        if source not in self.seen:  # what was sent before we heard of this sim is not a reply
            self._baseline[source] = {id(w): w.last_seq for w in self.participant.writers}
        self.seen.setdefault(source, {})[delivery.endpoint] = delivery.seq
        if delivery.topic != CLOCK_HASH:
            self._data = True

    def answer(self, next_wakeup: int, timers_ran: bool) -> None:
        """Send one answer per simulator heard from, when it may be waiting for one."""
        self._forget_gone()
        if not self.seen:
            return
        from rosl.idl import registry

        if self._writer is None:
            participant = self.participant
            self._writer = Writer(
                participant.transport, participant.sender, participant.next_endpoint(), TOPIC,
                TYPE,
            )  # fmt: skip
            self._class = registry.get_message_class(TYPE)
        store = registry.store()
        self.participant.flush()  # what the callbacks published goes out before the answer
        for source, handled in self.seen.items():
            if not (self._data or timers_ran or self._told.get(source) != next_wakeup):
                continue  # only /clock ticks that woke nothing: the sim is not waiting
            self._told[source] = next_wakeup
            baseline = self._baseline[source]
            writers = [w for w in self.participant.writers if w.last_seq != baseline.get(id(w), 0)]
            for writer in writers:
                baseline[id(writer)] = writer.last_seq
            ack = self._class(
                source=source,
                endpoints=list(handled),
                seqs=list(handled.values()),
                next_wakeup=next_wakeup,
                sent_topics=[w.topic for w in writers],
                sent_endpoints=[w.endpoint for w in writers],
                sent_seqs=[w.last_seq for w in writers],
            )
            self._writer.send(store.serialize(ack))
        self._data = False


# --- the simulator's side ----------------------------------------------------------------------


@dataclass(slots=True)
class _Peer:
    handled: dict[int, int] = field(default_factory=dict)  # our endpoint -> seq
    next_wakeup: int | None = None  # None: not told yet (wait for it on every /clock)
    sent: dict[tuple[int, int], int] = field(default_factory=dict)  # (topic, endpoint) -> seq
    stalled: bool = False


class LockstepSource:
    """The simulator's end: marks its publishers and waits for its subscribers' answers.

    Args:
        participant: the simulator's participant.
        timeout: seconds to wait for a peer before reporting it.
        on_stall: ``"continue"`` (go on without the peer until it answers again) or
            ``"stop"`` (raise :class:`LockstepStall`).
        log: where the stall report goes.
        extra_readers: other participants in this process (an in-process recorder) whose
            sockets must also have received the peers' replies before the next step.
    """

    def __init__(
        self,
        participant: Participant,
        *,
        timeout: float = 5.0,
        on_stall: str = "continue",
        log: Callable[[str], None] | None = None,
    ) -> None:
        self.participant = participant
        self.timeout = timeout
        self.on_stall = on_stall
        self._log = log or (lambda line: None)
        self.peers: dict[int, _Peer] = {}
        participant.discovery.on_gone.append(self._forget)
        self._step: list[tuple[str, int, int]] = []  # (topic, our endpoint, seq) sent this step
        self._subscribers: dict[str, list[int]] = {}
        self._generation = -1
        self.waits = 0  # steps that waited for at least one peer
        self.stalls = 0
        from rosl.idl import registry

        registry.get_message_class(TYPE)  # the store decodes only types it has loaded
        participant.listen(_TOPIC_HASH, self)

    def _forget(self, process: int) -> None:
        """A peer said goodbye or its lease ran out: stop waiting for it."""
        self.peers.pop(process, None)

    def mark(self, publisher: Publisher) -> None:
        """Send this publisher's messages as lock-stepped."""
        publisher._writer.flags |= Flags.LOCKSTEP

    def published(self, publisher: Publisher) -> None:
        """Note a message just published in this step."""
        writer = publisher._writer
        self._step.append((publisher.topic, writer.endpoint, writer.last_seq))

    def deliver(self, delivery: Delivery) -> None:
        """Take one answer (dispatched by the participant)."""
        from rosl.idl import registry

        try:
            ack: Any = registry.store().deserialize(delivery.payload, TYPE)  # fields by name
        except Exception:
            return
        if ack.source != self.participant.sender:
            return
        peer = self.peers.setdefault(delivery.sender, _Peer())
        for endpoint, seq in zip(ack.endpoints, ack.seqs, strict=False):
            peer.handled[int(endpoint)] = int(seq)
        peer.next_wakeup = int(ack.next_wakeup)
        for topic, endpoint, seq in zip(
            ack.sent_topics, ack.sent_endpoints, ack.sent_seqs, strict=False
        ):
            peer.sent[(int(topic), int(endpoint))] = int(seq)
        peer.stalled = False

    def _lockstep_subscribers(self) -> dict[str, list[int]]:
        graph = self.participant.graph
        if graph.generation != self._generation:
            self._generation = graph.generation
            answering = {p.sender for p in graph.processes() if p.lockstep}
            answering.discard(self.participant.sender)
            found: dict[str, list[int]] = {}
            for node, endpoint in graph.endpoints(SUBSCRIPTION):
                if node.process in answering:
                    peers = found.setdefault(endpoint.name, [])
                    if node.process not in peers:
                        peers.append(node.process)
            self._subscribers = found
        return self._subscribers

    def _missing(self, now_ns: int) -> list[tuple[int, str, int]]:
        """(process, topic, seq) answers still owed for this step."""
        subscribers = self._lockstep_subscribers()
        missing = []
        for topic, endpoint, seq in self._step:
            for process in subscribers.get(topic, ()):
                peer = self.peers.get(process)
                if peer is not None and peer.stalled:
                    continue
                if (
                    topic == "/clock"
                    and peer is not None
                    and peer.next_wakeup is not None
                    and (peer.next_wakeup < 0 or peer.next_wakeup > now_ns)
                ):
                    continue  # nothing of it wakes on this tick
                done = peer.handled.get(endpoint) if peer is not None else None
                if done is None or not _newer(done, seq):
                    missing.append((process, topic, seq))
        return missing

    def wait(self, now_ns: int) -> list[tuple[int, int, int, int]]:
        """Wait until this step's messages are handled; return the replies to expect.

        Returns:
            (process, topic hash, endpoint, seq) of each awaited peer's publishers: the
            simulator's readers must have seen these before stepping on.

        Raises:
            LockstepStall: a peer did not answer within the timeout and ``on_stall`` is stop.
        """
        awaited: set[int] = set()
        missing = self._missing(now_ns)
        if missing:
            self.waits += 1
            deadline = time.monotonic() + self.timeout
            while missing:
                awaited.update(p for p, _, _ in missing)
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    self._stall(missing)
                    break
                self.participant.poll(min(remaining, 0.05))
                missing = self._missing(now_ns)
        self._step.clear()
        replies = []
        for process in sorted(awaited):
            peer = self.peers.get(process)
            if peer is not None:
                replies += [(process, t, e, seq) for (t, e), seq in peer.sent.items()]
                peer.sent.clear()
        return replies

    def _stall(self, missing: list[tuple[int, str, int]]) -> None:
        self.stalls += 1
        graph = self.participant.graph
        names = []
        for process, topic, _ in missing:
            nodes = [n.fqn for n in graph.nodes() if n.process == process]
            pids = [p.pid for p in graph.processes() if p.sender == process]
            who = ", ".join(nodes) or f"process {process:016x}"
            pid = f" (pid {pids[0]})" if pids else ""
            names.append(f"{who}{pid} to handle {topic}")
            peer = self.peers.setdefault(process, _Peer())
            peer.stalled = True
        text = "; ".join(dict.fromkeys(names))
        if self.on_stall == "stop":
            raise LockstepStall(
                f"lock-step: waited {self.timeout:g} s for {text}; stopping (--on-stall stop)"
            )
        self._log(
            f"lock-step: waited {self.timeout:g} s for {text}; going on without it until it "
            "answers again"
        )

    def caught_up(self, participant: Participant, replies: list[tuple[int, int, int, int]]) -> bool:
        """Whether ``participant``'s reader has received every expected reply it listens to."""
        reader = participant.reader
        for process, topic, endpoint, seq in replies:
            if not (reader.want_all or topic in reader.wanted):
                continue
            stream = reader.streams.get((process, endpoint))
            if stream is None or not _newer(stream.last_seq, seq):
                return False
        return True

    def settle(self, replies: list[tuple[int, int, int, int]], timeout: float = 1.0) -> None:
        """Dispatch the peers' replies on the simulator's own participant (bounded wait)."""
        self.participant.poll(0.0)
        deadline = time.monotonic() + timeout
        while not self.caught_up(self.participant, replies) and time.monotonic() < deadline:
            self.participant.poll(0.005)
