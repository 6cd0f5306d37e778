"""Recording the bus to a rosbag2 folder of MCAP files.

Every datagram the recorder hears is written as it arrived: the payload bytes exactly as
sent (no re-serialisation), ``log_time`` = receive time, ``publish_time`` = send time, one
sequence counter per channel. Topic names and types come from discovery, so topics that
appear later are picked up; a type this process cannot read from .msg files is asked of the
publisher's process. Service requests and responses become ``<service>/_service_event``
messages as ROS 2's service introspection writes them. Schemas are read off the receiving
thread (``schemas.py``), so log times stay receive times when a topic appears mid-stream.
Chunks go to disk (flushed and fsynced) at least once a second, so a killed recorder loses at
most the last second; ``rosl bag reindex`` repairs such a folder. As rosbag2 does, a file is
split before the message that would make it longer than ``max_bag_duration`` (by log time)
or once it has reached ``max_bag_size`` bytes (counted as messages are written). A topic is
recorded with the first type seen on it; messages of another type on it are counted and
reported, never written (``selection.py``).

Messages of a topic the recorder cannot name yet (discovery has not shown its publisher) or
whose schema is still being read are held until it can, for at most ``PENDING_LIMIT_S``, and
within ``PENDING_MAX`` messages and ``PENDING_BYTES`` bytes (the buffers they keep alive): a
flood of datagrams on topics nobody announces costs a bounded amount of memory. What does not
fit, or waits too long, is counted and reported when the recording stops.
"""

from __future__ import annotations

import sys
import time
from collections import deque
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosl.bag import metadata
from rosl.bag.errors import BagError
from rosl.bag.inbox import Intake, Pending
from rosl.bag.schemas import PENDING_LIMIT_S, Schemas
from rosl.bag.selection import RECORDER_NODE, OtherTypes, Selection, sender_name
from rosl.bag.writer import BagFile
from rosl.bus.header import Kind, topic_hash, type_hash
from rosl.graph.records import CLIENT, PUBLISHER, SERVER, SUBSCRIPTION

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from rosl.bus.wire import Delivery
    from rosl.node.participant import Participant

FLUSH_EVERY_S = 1.0
PENDING_MAX = 20000  # messages held while their topic cannot be named yet
PENDING_BYTES = 32 * 1024 * 1024  # the bytes they may keep alive (see inbox.Pending)
LATCHED_SEEN = 4096  # messages of a latched topic remembered to drop a replayed duplicate
_SUBSCRIPTION_QOS = {"reliability": "RELIABLE", "durability": "VOLATILE", "history": "KEEP_LAST",
                     "depth": 1000}  # fmt: skip


@dataclass(slots=True)
class _Topic:
    info: metadata.TopicInfo
    encoding: str
    text: str
    endpoint: int
    sequence: int = 0
    latched: bool = False  # every publisher offered transient local: its history was asked for
    best_effort: bool = False  # a publisher offered best effort: so is the subscription (rosbag2)
    seen: set[tuple[int, int, int]] | None = None  # (sender, endpoint, seq) of a latched topic
    order: deque[tuple[int, int, int]] | None = None  # ``seen`` oldest first, to bound it

    def fresh(self, delivery: Delivery) -> bool:
        """Whether a latched topic's message was not recorded yet (live or replayed)."""
        if self.seen is None or self.order is None:
            return True
        key = (delivery.sender, delivery.endpoint, delivery.seq)
        if key in self.seen:
            return False
        self.seen.add(key)
        self.order.append(key)
        if len(self.order) > LATCHED_SEEN:
            self.seen.discard(self.order.popleft())
        return True


class Recorder:
    """Records a domain's traffic until stopped."""

    def __init__(
        self,
        folder: Path,
        *,
        topics: list[str] | None = None,
        exclude: str | None = None,
        services: bool = False,
        include_hidden: bool = False,
        max_bag_size: int = 0,
        max_bag_duration: float = 0.0,
        compression: str | None = None,
        domain: int | str | None = None,
        log: Callable[[str], None] | None = None,
        ros_distro: str | None = None,
    ) -> None:
        for flag, limit in (
            ("--max-bag-size", max_bag_size),
            ("--max-bag-duration", max_bag_duration),
        ):
            if limit < 0:
                raise BagError(f"{flag} must be 0 (no splitting) or more, not {limit}")
        self.folder = folder
        self.selection = Selection.parse(topics, exclude, include_hidden)
        self.services = services
        self.max_bag_size = max_bag_size
        self.max_bag_duration = max_bag_duration
        self.compression = compression
        self.domain = domain
        self.ros_distro = metadata.distro(ros_distro)
        self._log = log or (lambda line: print(line, file=sys.stderr, flush=True))
        self.participant: Participant | None = None
        self._file: BagFile | None = None
        self._files: list[metadata.FileInfo] = []
        self._topics: dict[str, _Topic] = {}
        self._names: dict[tuple[int, int], tuple[str, str, str]] = {}  # (topic hash, type hash)
        self._generation = -1
        self._synced = -1
        self._node_index = 0
        self._pending = Pending(PENDING_MAX, PENDING_BYTES)
        self._schemas: Schemas | None = None
        self._failure: BagError | None = None  # the first write the disk refused
        self._last_flush = time.monotonic()
        self.dropped_unknown = 0
        self.skipped_types: set[str] = set()
        self.other_types = OtherTypes(self._log)  # a second type on a recorded topic
        self.stopped = False
        self.sim_time = False  # set by record_at: log times come from a simulator's clock
        self._chunk_ns = 0
        self._intake: Intake | None = None  # the thread draining the socket, while run() runs

    # --- lifecycle ---------------------------------------------------------------------------

    def start(self) -> None:
        """Create the folder, join the bus, and start listening.

        Raises:
            BagError: the folder exists already or cannot be created.
        """
        from rosl.node.participant import Participant

        if self.folder.exists() and any(self.folder.iterdir()):
            raise BagError(f"Output folder '{self.folder}' already exists and is not empty")
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            probe = self.folder / ".rosl-write-test"
            probe.write_bytes(b"")
            probe.unlink()
        except OSError as err:
            raise BagError(f"cannot record into '{self.folder}': {err.strerror}") from None
        self.participant = Participant(self.domain)
        self._schemas = Schemas(self.participant, self._log)
        self._node_index = self.participant.add_node(self._describe)
        self.participant.graph.listeners.append(self._learn_names)
        if self.selection.topics is None or self.services:
            self.participant.listen_all()
        else:
            for name in sorted(self.selection.topics):
                self.participant.listen(topic_hash(name), _Ignore())
        discovery = self.participant.discovery
        discovery.wait_complete(discovery.query(), timeout=1.0)
        self._open_file()
        self._log("[INFO] [rosl_recorder]: Listening for topics...")
        self._sync_graph()
        self._log(f"[INFO] [rosl_recorder]: Recording to '{self.folder}'...")

    def step(self, timeout: float = 0.1) -> None:
        """Receive and write what arrives within ``timeout``; flush once a second."""
        assert self.participant is not None
        assert self._schemas is not None
        self._schemas.preload(self._wanted_types)
        if self._intake is None:
            self.participant.poll(timeout, sink=self._on_delivery)
        else:
            self._intake.wait(timeout)
            self._drain_inbox()
        self._sync_graph()
        now = time.monotonic()
        if self._pending:
            self._retry_pending(now)
        if now - self._last_flush >= FLUSH_EVERY_S:
            self._flush()
            self._last_flush = now

    def record_at(
        self,
        now_ns: int,
        caught_up: Callable[[], bool] | None = None,
        timeout: float = 1.0,
        only_from: int | None = None,
    ) -> None:
        """Write what has arrived as of sim time ``now_ns`` (a simulator's in-process recorder).

        Every message gets ``now_ns`` as log and publish time and the messages of one call are
        written in an order that does not depend on arrival order, so the same simulation gives
        the same bag. ``caught_up`` says when everything expected has arrived (bounded by
        ``timeout``). Chunks close every second of sim time; the file is fsynced at most once
        a second of wall time. ``only_from`` keeps only one process's messages (what came
        before a simulation started is left out, since its timing is not reproducible).
        """
        assert self.participant is not None
        self.sim_time = True
        arrived: list[Delivery] = []
        deadline = time.monotonic() + timeout
        self.participant.poll(0.0, sink=arrived.append)
        while caught_up is not None and not caught_up() and time.monotonic() < deadline:
            self.participant.poll(0.002, sink=arrived.append)
        self._sync_graph()
        if only_from is not None:
            arrived = [d for d in arrived if d.sender == only_from]
        arrived.sort(key=_arrival_free_order)
        for delivery in arrived:
            self._on_delivery(delivery._replace(received=now_ns, stamp=now_ns))
        if self._pending:
            self._retry_pending(time.monotonic())
        if now_ns - self._chunk_ns >= 1_000_000_000:
            self._chunk_ns = now_ns
            wall = time.monotonic()
            if self._file is not None:
                try:
                    self._file.flush(sync=False)
                except BagError as err:
                    raise self._failed(err) from None
                if wall - self._last_flush >= FLUSH_EVERY_S:
                    self._flush()
                    self._last_flush = wall

    def _drain_inbox(self) -> None:
        """Write what the intake thread queued (in arrival order)."""
        intake = self._intake
        if intake is None:
            return
        for delivery in intake.take():
            self._on_delivery(delivery)

    @property
    def held_bytes(self) -> int:
        """Bytes kept alive by the messages held until their topic is known (<= PENDING_BYTES)."""
        return self._pending.bytes

    def run(self, until: Callable[[], bool]) -> None:
        """Record until ``until()`` is true, the socket drained by a thread of its own.

        The intake thread only receives (checks, reassembles) and queues; this thread writes.
        A burst faster than the writer then waits in memory, within ``inbox.INBOX_BYTES``, instead
        of overflowing the socket's buffer in the kernel, where it would be lost.
        """
        assert self.participant is not None, "start() first"
        self._intake = Intake(self.participant)
        try:
            while not until():
                self.step(0.1)
        finally:
            self._intake.stop()
            self._drain_inbox()
            self._intake = None

    def close(self) -> None:
        """Finish the MCAP file(s) with their index and write metadata.yaml (idempotent).

        Raises:
            BagError: the disk refused a write (the first such error, also when it came
                before); the unfinished file is left for ``rosl bag reindex``.
        """
        if self.stopped:
            return
        self.stopped = True
        if self._schemas is not None:
            self._schemas.stop()  # what is still held is read here
        try:
            if self._failure is None:
                if (
                    self.participant is not None
                    and not self.participant.closed
                    and not self.sim_time
                ):
                    self.participant.poll(0.0, sink=self._on_delivery)
                if self._pending:
                    self._retry_pending(time.monotonic() + PENDING_LIMIT_S + 1)
            self._close_file()
        finally:
            if self.participant is not None:
                self.participant.close()
        if self._failure is not None:  # no metadata.yaml: reindex rebuilds it from the files
            raise self._failure
        infos = [t.info for t in self._topics.values()]
        if self.sim_time:  # the same run gives the same metadata
            infos.sort(key=lambda info: info.name)
        metadata.write(self.folder, infos, self._files, ros_distro=self.ros_distro)
        total = sum(t.count for t in infos)
        lost = self.participant.reader.lost() if self.participant is not None else 0
        self._log(
            f"[INFO] [rosl_recorder]: Recording stopped: {total} messages on "
            f"{sum(1 for t in infos if t.count)} topics, {lost} lost in transit"
            + (
                f", {self.dropped_unknown} of unknown topics dropped"
                if self.dropped_unknown
                else ""
            )
            + self.other_types.note()
        )

    # --- files -------------------------------------------------------------------------------

    def _open_file(self) -> None:
        index = len(self._files)
        path = self.folder / f"{self.folder.name}_{index}.mcap"
        current = BagFile(
            path, compression=self.compression, library="rosl",
            version=metadata.VERSIONS[self.ros_distro],
        )  # fmt: skip
        self._files.append(current.info)
        self._file = current
        for name, topic in self._topics.items():  # as rosbag2 does: every topic in every file
            self._channel(current, name, topic)

    def _close_file(self) -> None:
        current = self._file
        if current is None:
            return
        self._file = None
        if self._failure is not None:  # the disk refused a write: the file stays unfinished
            current.abandon()
            return
        infos = [t.info for t in self._topics.values()]
        information = metadata.information(infos, self._files, ros_distro=self.ros_distro)
        try:
            current.finish(information, self.ros_distro)
        except BagError as err:
            current.abandon()
            raise self._failed(err) from None

    def _flush(self) -> None:
        current = self._file
        if current is None:
            return
        try:
            current.flush()
        except BagError as err:
            raise self._failed(err) from None

    def _failed(self, err: BagError) -> BagError:
        """The error of a write the disk refused, kept: :meth:`close` raises it again."""
        if self._failure is None:
            self._failure = err
        return self._failure

    def _split_before(self, current: BagFile, log_time: int) -> bool:
        """Whether a message logged at ``log_time`` belongs in a new file (rosbag2's rule)."""
        if not current.info.count:
            return False
        if self.max_bag_duration and (
            log_time - current.info.start_ns > self.max_bag_duration * 1_000_000_000
        ):
            return True
        if not self.max_bag_size or current.size() < self.max_bag_size:
            return False
        if self.compression and current.unchunked:  # compressed, the chunk may be smaller
            try:
                current.flush(sync=False)
            except BagError as err:
                raise self._failed(err) from None
        return current.size() >= self.max_bag_size

    # --- messages ----------------------------------------------------------------------------

    def _on_delivery(self, delivery: Delivery) -> None:
        if not self._take(delivery):
            self.dropped_unknown += self._pending.add(delivery, time.monotonic())

    def _take(self, delivery: Delivery) -> bool:
        """Record a delivery (or leave it out on purpose); False while it must be held."""
        if delivery.kind == Kind.DATA:
            return self._record_data(delivery)
        if delivery.kind == Kind.REPLAY:
            return self._record_replay(delivery)
        if self.services and delivery.kind in (Kind.REQUEST, Kind.RESPONSE):
            return self._record_service(delivery)
        return True

    def _learn_names(self) -> bool:
        """Remember the name and type of every endpoint the graph shows (after each change).

        Called on discovery's thread as the change happens, so a process that announces itself
        and leaves before the recording thread reaches its messages still has them named.
        """
        participant = self.participant
        if participant is None or participant.closed:
            return False
        names: dict[tuple[int, int], tuple[str, str, str]] = {}
        for _node, endpoint in participant.graph.endpoints():
            key = (topic_hash(endpoint.name), type_hash(endpoint.type))
            qos = endpoint.qos if endpoint.kind == PUBLISHER else {}
            if key not in names or qos:
                names[key] = (endpoint.name, endpoint.type, endpoint.kind)
        self._names = {**self._names, **names}  # one assignment: the recording thread reads it
        return True

    def _resolve(self, delivery: Delivery, kinds: tuple[str, ...]) -> tuple[str, str, str] | None:
        assert self.participant is not None
        generation = self.participant.graph.generation
        if generation != self._generation:  # also changes made before the listener was added
            self._generation = generation
            self._learn_names()
        found = self._names.get((delivery.topic, delivery.type))
        if found is None or found[2] not in kinds:
            return None
        return found

    def _record_data(self, delivery: Delivery) -> bool:
        found = self._resolve(delivery, (PUBLISHER, SUBSCRIPTION))
        if found is None:
            return False
        name, type_name, _ = found
        if not self.selection.wanted(name) or self._other_type(name, type_name, delivery):
            return True
        topic = self._subscribe(name, type_name)
        if topic is None:
            return False
        if topic.seen is None or topic.fresh(delivery):
            self._write(name, topic, delivery, bytes(delivery.payload))
        return True

    def _record_replay(self, delivery: Delivery) -> bool:
        """A publisher's history, sent because this recorder asked for it (transient local)."""
        assert self.participant is not None
        address = delivery.address
        if address is None or address[0] != self.participant.sender:
            return True  # another process's late subscription asked for it
        found = self._resolve(delivery, (PUBLISHER, SUBSCRIPTION))
        if found is None:
            return True
        topic = self._topics.get(found[0])
        if topic is None or topic.endpoint != address[1] or topic.info.type != found[1]:
            return True
        if topic.fresh(delivery):
            self._write(topic.info.name, topic, delivery, bytes(delivery.payload))
        return True

    def _record_service(self, delivery: Delivery) -> bool:
        from rosl.idl.errors import InterfaceError
        from rosl.node.service_events import event_from_delivery, event_topic, event_type_name

        found = self._resolve(delivery, (SERVER, CLIENT))
        if found is None:
            return False
        service, service_type, _ = found
        name = event_topic(service)
        if self.selection.excluded(name):
            return True
        try:
            event = event_from_delivery(delivery, service_type)
        except InterfaceError:
            if service_type not in self.skipped_types:
                self.skipped_types.add(service_type)
                self._log(f"[WARN] [rosl_recorder]: service type {service_type} is unknown here; "
                          f"events of {service} are not recorded")  # fmt: skip
            return True
        if event is None:
            return True
        from rosl.idl import registry

        if self._other_type(name, event_type_name(service_type), delivery):
            return True
        topic = self._subscribe(name, event_type_name(service_type), qos={"depth": 10})
        if topic is None:
            return False
        self._write(name, topic, delivery, registry.store().serialize(event))
        return True

    def _write(self, name: str, topic: _Topic, delivery: Delivery, data: bytes) -> None:
        current = self._file
        assert current is not None
        if (self.max_bag_duration or self.max_bag_size) and self._split_before(
            current, delivery.received
        ):
            self._close_file()
            self._open_file()
            current = self._file
            assert current is not None
        try:
            current.write(
                self._channel(current, name, topic), delivery.received, delivery.stamp,
                topic.sequence + 1, data,
            )  # fmt: skip
        except BagError as err:  # a chunk went out and the disk refused it
            raise self._failed(err) from None
        topic.sequence += 1
        topic.info.count += 1

    def _channel(self, current: BagFile, name: str, topic: _Topic) -> int:
        try:
            return current.channel(topic.info, topic.encoding, topic.text)
        except BagError as err:
            raise self._failed(err) from None

    def _other_type(self, name: str, type_name: str, delivery: Delivery) -> bool:
        """Whether ``name`` is recorded with another type (the message is counted, not written)."""
        existing = self._topics.get(name)
        if existing is None or existing.info.type == type_name:  # every message: cheap first
            return False
        assert self.participant is not None
        graph = self.participant.graph
        return self.other_types.left_out(
            name, existing.info.type, type_name, lambda: sender_name(graph, delivery, name)
        )

    def _subscribe(
        self, name: str, type_name: str, qos: dict[str, Any] | None = None
    ) -> _Topic | None:
        """Start recording a topic (its schema known); None while its type is being asked for."""
        existing = self._topics.get(name)
        if existing is not None:
            return existing
        assert self._schemas is not None
        found = self._schemas.get(type_name)
        if found is None:
            return None
        encoding, text, digest = found
        assert self.participant is not None
        info = metadata.TopicInfo(
            name, type_name, qos=self._qos(name, type_name, qos), type_hash=digest
        )
        topic = _Topic(info, encoding, text, self.participant.next_endpoint())
        topic.best_effort = any(q.get("reliability") == "best_effort" for q in info.qos)
        self._topics[name] = topic
        if self._file is not None:  # its channel now: a topic without messages is in the file
            self._channel(self._file, name, topic)
        if (
            qos is None and info.qos and all(q["durability"] == "transient_local" for q in info.qos)
        ):  # as rosbag2 asks: transient local when every publisher offers it, and then the
            # late-joiner's history comes (what a late subscriber of the topic gets)
            topic.latched, topic.seen, topic.order = True, set(), deque()
            self.participant.discovery.send(
                {"op": "replay", "topic": name,
                 "target": [f"{self.participant.sender:016x}", topic.endpoint]}
            )  # fmt: skip
        self._log(f"[INFO] [rosl_recorder]: Subscribed to topic '{name}'")
        self.participant.discovery.changed()
        return topic

    def _sync_graph(self) -> None:
        """Subscribe to every wanted topic (and service) as soon as the graph shows it."""
        assert self.participant is not None
        assert self._schemas is not None
        graph = self.participant.graph
        if graph.generation == self._synced and not self._schemas.arrived:
            return
        self._schemas.arrived = False  # before looking: a schema arriving now is seen next time
        self._synced = graph.generation
        for name, type_name, service in self._unrecorded():
            if not service:
                self._subscribe(name, type_name)
                continue
            try:
                self._subscribe(name, type_name, qos={"depth": 10})
            except Exception:
                continue

    def _unrecorded(self) -> Iterator[tuple[str, str, bool]]:
        """(topic, type, is a service's event topic) of what the graph offers, not yet taken."""
        from rosl.node.service_events import event_topic, event_type_name

        assert self.participant is not None
        graph = self.participant.graph
        for _, endpoint in graph.endpoints(PUBLISHER):
            if endpoint.name not in self._topics and self.selection.wanted(endpoint.name):
                yield endpoint.name, endpoint.type, False
        if self.services:
            for _, endpoint in graph.endpoints(SERVER):
                name = event_topic(endpoint.name)
                if name not in self._topics and not self.selection.excluded(name):
                    yield name, event_type_name(endpoint.type), True

    def _describe(self) -> Any:
        """The recorder as a node in the graph, subscribed to what it records."""
        from rosl.graph.records import EndpointRecord, NodeRecord

        assert self.participant is not None
        endpoints = tuple(
            EndpointRecord(
                SUBSCRIPTION,
                name,
                t.info.type,
                t.endpoint,
                dict(
                    _SUBSCRIPTION_QOS,
                    durability="TRANSIENT_LOCAL" if t.latched else "VOLATILE",
                    reliability="BEST_EFFORT" if t.best_effort else "RELIABLE",
                ),
                {"received": t.info.count},
            )
            for name, t in list(self._topics.items())
        )
        return NodeRecord(RECORDER_NODE, "/", self.participant.sender, self._node_index, endpoints)

    def _qos(self, name: str, type_name: str, given: dict[str, Any] | None) -> list[dict[str, Any]]:
        """The offered QoS of the topic's publishers of the recorded type (or ``given``)."""
        assert self.participant is not None
        if given is not None:
            return [metadata.qos_entry(given)]
        graph = self.participant.graph
        entries = [
            metadata.qos_entry(e.qos)
            for _, e in graph.endpoints(PUBLISHER, name)
            if e.type == type_name
        ]
        return sorted(entries, key=repr)

    def _wanted_types(self) -> set[str]:  # the schemas thread
        """The types of the graph's wanted topics (and services) not yet recorded."""
        return {type_name for _, type_name, _ in self._unrecorded()}

    def _retry_pending(self, now: float) -> None:
        """Record the held messages whose topic is known now; drop those held too long."""
        self._pending.retry(self._take)
        self.dropped_unknown += self._pending.expire(now, PENDING_LIMIT_S)


def _arrival_free_order(delivery: Delivery) -> tuple[int, int, int, bytes]:
    """Topic, sequence, endpoint, bytes: the same for the same messages, however they came."""
    return (delivery.topic, delivery.seq, delivery.endpoint, bytes(delivery.payload))


class _Ignore:
    """A handler for topics the recorder listens to through its sink."""

    def deliver(self, delivery: Delivery) -> None:
        """Unused: the recorder reads through ``poll(sink=...)``."""
