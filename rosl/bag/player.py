"""``rosl bag play``: a recording put back on the bus, bytes unchanged, with its original timing.

A node ``rosbag2_player`` announces one publisher per played topic (the recorded type and
offered QoS, after ``--remap``), then each message's recorded bytes are sent when the playback
clock reaches its log time: the clock starts at the bag's first message (plus
``--start-offset``) and runs at ``--rate``. A reader thread keeps up to
``--read-ahead-queue-size`` messages ready. With ``--clock`` the playback clock is published on
``/clock`` so sim-time nodes follow the bag. On a terminal, SPACE pauses and resumes, → sends
the next message while paused, ↑/↓ change the rate by 10%.

A topic name is resolved as the ROS 2 player's publishers resolve it, in the node's namespace
``/``: a bag written by another tool may hold ``AAA``, played on ``/AAA`` (``--topics`` and
``--remap`` name it either way). The bag's start and length are those of the messages its files
hold (:func:`rosl.bag.info.extent`: message indexes, not the Statistics record, which a writer
can get wrong). Messages that are not CDR are refused as rosbag2 refuses them.
"""

from __future__ import annotations

import collections
import contextlib
import queue
import threading
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.bag.controls import HINTS, Keyboard, Timeline
from rosl.bag.errors import BagError
from rosl.bag.info import extent, refuse_foreign_encodings
from rosl.bag.reader import BagMessage, iter_bag
from rosl.bag.trim import Scan, SourceChannel, scan, unfinished_warning

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from rosl.bus.wire import Writer
    from rosl.graph.records import NodeRecord
    from rosl.node.participant import Participant

NS = 1_000_000_000
NODE = "rosbag2_player"
_PASS = object()  # end of one pass through the bag (more follow with --loop)
_DONE = object()


@dataclass(frozen=True, slots=True)
class PlayOptions:
    """How to play a bag (``ros2 bag play``'s options)."""

    rate: float = 1.0
    loop: bool = False
    clock_hz: float | None = None  # None: no /clock
    topics: tuple[str, ...] = ()  # empty: every topic
    start_offset: float = 0.0
    remap: tuple[tuple[str, str], ...] = ()
    read_ahead: int = 1000
    domain: int | str | None = None
    keyboard: bool = False
    start_paused: bool = False
    discovery_wait: float = 0.3


@dataclass(slots=True)
class PlayResult:
    """What was played."""

    played: dict[str, int] = field(default_factory=dict)  # topic as published -> messages
    passes: int = 0
    stopped: bool = False

    def summary(self) -> str:
        """One line: messages played per topic."""
        total = sum(self.played.values())
        topics = ", ".join(f"{name} {count}" for name, count in sorted(self.played.items()))
        passes = f" in {self.passes} passes" if self.passes > 1 else ""
        stopped = " (stopped)" if self.stopped else ""
        return f"played {total} messages{passes}{stopped}" + (f": {topics}" if topics else "")


def parse_remap(rules: list[str] | tuple[str, ...]) -> tuple[tuple[str, str], ...]:
    """``from:=to`` rules as (from, to) pairs of absolute topic names.

    Raises:
        BagError: a rule without ``:=`` or with an empty side.
    """
    pairs = []
    for rule in rules:
        source, sep, target = rule.partition(":=")
        if not sep or not source or not target:
            raise BagError(f"--remap '{rule}' is not of the form from:=to")
        pairs.append(("/" + source.lstrip("/"), "/" + target.lstrip("/")))
    return tuple(pairs)


class _Outlet:
    """The publisher of one played topic (keeps history when it was transient-local)."""

    def __init__(self, writer: Writer, qos: dict[str, Any]) -> None:
        self.writer = writer
        self.qos = qos
        keep = str(qos.get("durability", "")).upper() == "TRANSIENT_LOCAL"
        depth = max(1, int(qos.get("depth", 1) or 1))
        self.history: collections.deque[tuple[int, bytes]] | None = (
            collections.deque(maxlen=depth) if keep else None
        )
        cache = getattr(writer.transport, "keep_history", None)
        if keep and cache is not None:  # a transport that keeps history itself (Zenoh)
            cache(writer.topic, depth, str(qos.get("reliability", "")).upper() != "BEST_EFFORT")

    def send(self, data: bytes) -> None:
        seq = self.writer.send(data)
        if self.history is not None:
            self.history.append((seq, data))

    def replay(self, target: tuple[int, int]) -> None:
        """Send the kept history to one late transient-local subscriber."""
        from rosl.bus.header import Kind

        for seq, data in list(self.history or ()):
            self.writer.send(data, kind=Kind.REPLAY, address=(*target, 0), seq=seq)


def qos_words(channel: SourceChannel) -> dict[str, Any]:
    """Discovery's QoS words from the first offered profile the recorder wrote."""
    first = (channel.offered_qos() or [{}])[0]
    return {
        "reliability": str(first.get("reliability", "reliable")).upper(),
        "durability": str(first.get("durability", "volatile")).upper(),
        "history": str(first.get("history", "keep_last")).upper(),
        "depth": int(first.get("depth", 10) or 10),
    }


class Player:
    """Plays one bag on the bus; :meth:`play` runs to the end (or :meth:`stop`)."""

    def __init__(
        self, bag: Path, options: PlayOptions, log: Callable[[str], None] | None = None
    ) -> None:
        if options.rate <= 0:
            raise BagError(f"--rate must be greater than 0 (got {options.rate})")
        if options.clock_hz is not None and options.clock_hz <= 0:
            raise BagError(f"--clock must be a rate greater than 0 Hz (got {options.clock_hz:g})")
        if options.read_ahead < 1:
            raise BagError("--read-ahead-queue-size must be at least 1")
        self.bag = bag
        self.options = options
        self._log = log or (lambda line: None)
        self._stop = threading.Event()
        self._queue: queue.Queue[Any] = queue.Queue(maxsize=options.read_ahead)
        self._outlets: dict[str, _Outlet] = {}
        self._clock: Writer | None = None
        self._clock_message: Callable[[int], bytes] = lambda bag_ns: b""
        self._next_tick = 0.0
        self._step = False
        self._index = 0
        self.participant: Participant | None = None
        self.result = PlayResult()

    def stop(self) -> None:
        """Ask playback to end (safe from a signal handler)."""
        self._stop.set()

    def play(self) -> PlayResult:
        """Play the bag; return what was played.

        Raises:
            BagError: the bag cannot be read.
        """
        keys = Keyboard(self.options.keyboard)
        if self.options.start_paused and not keys.active:
            raise BagError("--start-paused needs the keyboard: stdin is not a terminal")
        found = scan(self.bag)
        for path in found.unfinished:
            self._log(unfinished_warning(path))
        resolved = self._resolve(found)
        wanted = self._select(resolved)
        refuse_foreign_encodings(found, wanted)
        remap = dict(self.options.remap)
        names = {topic: remap.get(resolved[topic], resolved[topic]) for topic in wanted}
        span = extent(found.files)
        start = span.start_ns + round(self.options.start_offset * NS)
        reader = threading.Thread(target=self._produce, args=(wanted, start), daemon=True)
        try:
            self._join(found, names)
            reader.start()
            with keys:
                self._log(f"[INFO] [{NODE}]: Set rate to {self.options.rate:g}")
                for line in HINTS if keys.active else ():
                    self._log(f"[INFO] [{NODE}]: {line}")
                count = sum(span.counts.get(t, 0) for t in wanted)
                seconds = (span.end_ns - span.start_ns) / NS
                self._log(f"[INFO] [{NODE}]: Playing {count} messages on {len(wanted)} topics "
                          f"({seconds:.1f} s of recording)")  # fmt: skip
                self._run(keys, start, names)
        finally:
            self._stop.set()
            with contextlib.suppress(queue.Empty):
                while True:
                    self._queue.get_nowait()
            if self.participant is not None:
                self.participant.close()
        return self.result

    # --- setup -------------------------------------------------------------------------------

    def _resolve(self, found: Scan) -> dict[str, str]:
        """Each bag topic's full name in the player's namespace (``AAA`` is ``/AAA``)."""
        from rosl.node.errors import InvalidNameError
        from rosl.node.names import expand

        resolved = {}
        for topic in sorted(found.channels):
            try:
                resolved[topic] = expand(topic, NODE, "/")
            except InvalidNameError as err:
                self._log(f"[WARN] [{NODE}]: topic {topic!r} is not played: {err}")
        return resolved

    def _select(self, resolved: dict[str, str]) -> set[str]:
        """The bag topics to play (``--topics`` names them resolved: ``AAA`` or ``/AAA``)."""
        if not self.options.topics:
            return set(resolved)
        asked = {"/" + name.lstrip("/") for name in self.options.topics}
        for name in sorted(asked - set(resolved.values())):
            self._log(f"[WARN] [{NODE}]: topic {name} is not in the bag")
        return {topic for topic, name in resolved.items() if name in asked}

    def _join(self, found: Scan, names: dict[str, str]) -> None:
        """Join the bus as rosbag2_player with a publisher per topic; let discovery settle."""
        from rosl.bus.wire import Writer
        from rosl.node.participant import Participant

        participant = self.participant = Participant(self.options.domain)
        for topic in sorted(names):
            channel = found.channels[topic]
            name = names[topic]
            writer = Writer(
                participant.transport, participant.sender, participant.next_endpoint(),
                name, channel.type,
            )  # fmt: skip
            outlet = self._outlets[topic] = _Outlet(writer, qos_words(channel))
            if outlet.history is not None:
                participant.add_replayer(name, outlet)
        if self.options.clock_hz is not None:
            self._clock_message = _clock_serializer()
            self._clock = Writer(
                participant.transport, participant.sender, participant.next_endpoint(),
                "/clock", "rosgraph_msgs/msg/Clock",
            )  # fmt: skip
        self._answer_typedefs(found)
        self._index = participant.add_node(lambda: self._describe(found, names))
        participant.discovery.changed()
        participant.discovery.wait_complete(participant.discovery.query(), timeout=1.0)
        self._stop.wait(self.options.discovery_wait)

    def _describe(self, found: Scan, names: dict[str, str]) -> NodeRecord:
        from rosl.graph.records import PUBLISHER, EndpointRecord, NodeRecord

        assert self.participant is not None
        endpoints = [
            EndpointRecord(PUBLISHER, names[topic], found.channels[topic].type,
                           outlet.writer.endpoint, outlet.qos, {"sent": outlet.writer.sent})
            for topic, outlet in self._outlets.items()
        ]  # fmt: skip
        if self._clock is not None:
            qos = {"reliability": "RELIABLE", "durability": "VOLATILE", "depth": 10}
            endpoints.append(
                EndpointRecord(PUBLISHER, "/clock", "rosgraph_msgs/msg/Clock",
                               self._clock.endpoint, qos, {"sent": self._clock.sent})
            )  # fmt: skip
        return NodeRecord(NODE, "/", self.participant.sender, self._index, tuple(endpoints))

    def _answer_typedefs(self, found: Scan) -> None:
        """Describe the bag's types to recorders that ask (they may not know them locally)."""
        assert self.participant is not None
        discovery = self.participant.discovery
        previous = discovery.handlers.get("typedef_request")
        hashes = {
            e["topic_metadata"]["type"]: e["topic_metadata"].get("type_description_hash", "")
            for e in (found.info or {}).get("topics_with_message_count", [])
        }
        schemas = {c.type: c for c in found.channels.values() if c.schema_encoding}

        def answer(message: dict[str, Any]) -> None:
            channel = schemas.get(str(message.get("type")))
            if channel is None:
                if previous is not None:
                    previous(message)
                return
            discovery.send({
                "op": "typedef", "type": channel.type, "encoding": channel.schema_encoding,
                "text": channel.schema_data.decode(errors="replace"),
                "hash": hashes.get(channel.type, ""),
            })  # fmt: skip

        discovery.handlers["typedef_request"] = answer

    # --- reading -----------------------------------------------------------------------------

    def _produce(self, wanted: set[str], start: int) -> None:
        """The read-ahead thread: every pass of the bag into the queue."""
        try:
            while not self._stop.is_set():
                count = 0
                for message in self._messages(wanted, start):
                    if not self._put(message):
                        return
                    count += 1
                if not (self.options.loop and count):
                    break
                if not self._put(_PASS):
                    return
            self._put(_DONE)
        except Exception as err:
            self._put(err)

    def _messages(self, wanted: set[str], start: int) -> Iterator[BagMessage]:
        from mcap.exceptions import McapError

        if not wanted:
            return
        try:
            for message in iter_bag(self.bag, wanted):
                if message.log_time >= start:
                    yield message
        except McapError as err:
            raise BagError(f"cannot read {self.bag}: {err}") from None

    def _put(self, item: object) -> bool:
        while not self._stop.is_set():
            try:
                self._queue.put(item, timeout=0.1)
            except queue.Full:
                continue
            return True
        return False

    # --- playing -----------------------------------------------------------------------------

    def _run(self, keys: Keyboard, start: int, names: dict[str, str]) -> None:
        item = self._take(keys, None)  # the first message is read before the clock starts
        timeline = Timeline(start, self.options.rate)
        timeline.paused = self.options.start_paused
        self.result.passes = 1
        self._tick(timeline, force=True)
        while item is not None and item is not _DONE:
            if item is _PASS:
                self.result.passes += 1
                self._log(f"[INFO] [{NODE}]: Loop: pass {self.result.passes}")
                timeline.jump(start)
            elif isinstance(item, BaseException):
                raise item
            elif self._wait_for(item.log_time, keys, timeline):
                self._outlets[item.topic].send(item.data)
                name = names[item.topic]
                self.result.played[name] = self.result.played.get(name, 0) + 1
            item = self._take(keys, timeline)
        self.result.stopped = self._stop.is_set()

    def _take(self, keys: Keyboard, timeline: Timeline | None) -> Any:
        """The next item read ahead (None once stopped)."""
        while not self._stop.is_set():
            try:
                return self._queue.get(timeout=0.05)
            except queue.Empty:
                if timeline is not None:
                    self._service(keys, timeline, 0.0)
        return None

    def _wait_for(self, bag_ns: int, keys: Keyboard, timeline: Timeline) -> bool:
        """Wait until the playback clock reaches ``bag_ns`` (or → is pressed while paused)."""
        while not self._stop.is_set():
            remaining = timeline.seconds_until(bag_ns)
            if self._step:
                self._step = False
                timeline.jump(max(bag_ns, timeline.now()))
                return True
            if remaining <= 0:
                return True
            self._service(keys, timeline, min(remaining, 0.05))
        return False

    def _service(self, keys: Keyboard, timeline: Timeline, timeout: float) -> None:
        """Publish /clock when due; read keys (or sleep) for up to ``timeout``."""
        self._tick(timeline)
        if self._clock is not None:
            timeout = min(timeout, max(0.0, self._next_tick - time.monotonic()))
        if not keys.active:
            if timeout > 0:
                self._stop.wait(timeout)
            return
        for command in keys.read(timeout):
            if command == "pause":
                timeline.set_paused(not timeline.paused)
                self._log(f"[INFO] [{NODE}]: {'Pausing' if timeline.paused else 'Resuming'} play.")
            elif command == "next" and timeline.paused:
                self._step = True
            elif command in ("faster", "slower"):
                timeline.set_rate(timeline.rate * (1.1 if command == "faster" else 0.9))
                self._log(f"[INFO] [{NODE}]: Set rate to {timeline.rate:g}")

    def _tick(self, timeline: Timeline, force: bool = False) -> None:
        if self._clock is None or self.options.clock_hz is None:
            return
        now = time.monotonic()
        if not force and now < self._next_tick:
            return
        period = 1.0 / self.options.clock_hz
        self._next_tick = now + period if force else self._next_tick + period
        if self._next_tick < now:  # fell behind (a slow send): keep the rate, not the backlog
            self._next_tick = now + period
        self._clock.send(self._clock_message(timeline.now()))


def _clock_serializer() -> Callable[[int], bytes]:
    """A function making /clock payloads (its types loaded now, not at the first tick)."""
    from rosl.idl import registry

    clock_type = registry.get_message_class("rosgraph_msgs/msg/Clock")
    time_type = registry.get_message_class("builtin_interfaces/msg/Time")
    store = registry.store()

    def serialize(bag_ns: int) -> bytes:
        sec, nanosec = divmod(bag_ns, NS)
        return store.serialize(clock_type(clock=time_type(sec=sec, nanosec=nanosec)))

    serialize(0)
    return serialize
