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

import contextlib
import mmap
import os
import sys
import time
from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, BinaryIO, NamedTuple

from rosl.bag import metadata
from rosl.bag.errors import BagError
from rosl.bag.schemas import PENDING_LIMIT_S, Schemas
from rosl.bag.selection import RECORDER_NODE, OtherTypes, Selection, sender_name
from rosl.bus.header import Kind, topic_hash, type_hash
from rosl.graph.records import CLIENT, PUBLISHER, SERVER, SUBSCRIPTION

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from rosl.bus.wire import Delivery
    from rosl.node.participant import Participant

FLUSH_EVERY_S = 1.0
PENDING_MAX = 20000  # messages held while their topic cannot be named yet
PENDING_BYTES = 32 * 1024 * 1024  # the bytes they may keep alive (see _Pending)
HELD_OVERHEAD = 512  # bytes per held message besides its buffer: tuple, view, bookkeeping
MESSAGE_RECORD = 31  # bytes of an MCAP message record besides its data
_SUBSCRIPTION_QOS = {"reliability": "RELIABLE", "durability": "VOLATILE", "history": "KEEP_LAST",
                     "depth": 1000}  # fmt: skip


@dataclass(slots=True)
class _Topic:
    info: metadata.TopicInfo
    encoding: str
    text: str
    endpoint: int
    sequence: int = 0


@dataclass(slots=True)
class _File:
    path: Path
    handle: BinaryIO
    writer: Any
    info: metadata.FileInfo
    schemas: dict[str, int] = field(default_factory=dict)
    channels: dict[str, int] = field(default_factory=dict)
    position: int = 0  # where the handle was after the last chunk went out
    unchunked: int = 0  # message bytes in the chunk still being built

    def size(self) -> int:
        """The file's size so far, the chunk being built counted uncompressed."""
        return self.handle.tell() + self.unchunked

    def chunk_written(self) -> None:
        """Note that the chunk being built went to the handle (a flush)."""
        self.position = self.handle.tell()
        self.unchunked = 0


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
        self._log = log or (lambda line: print(line, file=sys.stderr, flush=True))
        self.participant: Participant | None = None
        self._file: _File | None = None
        self._files: list[metadata.FileInfo] = []
        self._topics: dict[str, _Topic] = {}
        self._names: dict[tuple[int, int], tuple[str, str, str]] = {}  # (topic hash, type hash)
        self._generation = -1
        self._synced = -1
        self._node_index = 0
        self._pending = _Pending(PENDING_MAX, PENDING_BYTES)
        self._schemas: Schemas | None = None
        self._failure: BagError | None = None  # the first write the disk refused
        self._last_flush = time.monotonic()
        self.dropped_unknown = 0
        self.skipped_types: set[str] = set()
        self.other_types = OtherTypes(self._log)  # a second type on a recorded topic
        self.stopped = False
        self.sim_time = False  # set by record_at: log times come from a simulator's clock
        self._chunk_ns = 0

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
        self.participant.poll(timeout, sink=self._on_delivery)
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
                    self._file.writer.flush()
                except OSError as err:
                    raise self._failed(self._file, err) from None
                self._file.chunk_written()
                if wall - self._last_flush >= FLUSH_EVERY_S:
                    self._flush()
                    self._last_flush = wall

    @property
    def held_bytes(self) -> int:
        """Bytes kept alive by the messages held until their topic is known (<= PENDING_BYTES)."""
        return self._pending.bytes

    def run(self, until: Callable[[], bool]) -> None:
        """Record until ``until()`` is true."""
        while not until():
            self.step(0.1)

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
        metadata.write(self.folder, infos, self._files)
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
        from mcap.writer import CompressionType, Writer

        index = len(self._files)
        path = self.folder / f"{self.folder.name}_{index}.mcap"
        compression = {
            None: CompressionType.NONE, "none": CompressionType.NONE,
            "zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4,
        }[self.compression]  # fmt: skip
        try:
            handle = path.open("wb")
        except OSError as err:
            raise BagError(f"cannot create {path}: {err.strerror}") from None
        writer = Writer(handle, compression=compression, chunk_size=4 * 1024 * 1024)
        writer.start(profile="ros2", library="rosl")
        info = metadata.FileInfo(path.name)
        self._files.append(info)
        self._file = _File(path, handle, writer, info)

    def _close_file(self) -> None:
        current = self._file
        if current is None:
            return
        self._file = None
        if self._failure is not None:  # the disk refused a write: the file stays unfinished
            with contextlib.suppress(OSError):
                current.handle.close()
            return
        try:
            current.writer.finish()
            current.handle.flush()
            os.fsync(current.handle.fileno())
            current.handle.close()
        except OSError as err:
            with contextlib.suppress(OSError):
                current.handle.close()
            self._failure = BagError(f"cannot finish {current.path}: {err.strerror}")
            raise self._failure from None

    def _flush(self) -> None:
        current = self._file
        if current is None:
            return
        try:
            current.writer.flush()
            os.fsync(current.handle.fileno())
        except OSError as err:
            raise self._failed(current, err) from None
        current.chunk_written()

    def _failed(self, current: _File, err: OSError) -> BagError:
        """The error of a write the disk refused, kept: :meth:`close` raises it again."""
        if self._failure is None:
            self._failure = BagError(f"cannot write {current.path}: {err.strerror} (disk full?)")
        return self._failure

    def _split_before(self, current: _File, log_time: int) -> bool:
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
                current.writer.flush()
            except OSError as err:
                raise self._failed(current, err) from None
            current.chunk_written()
        return current.size() >= self.max_bag_size

    # --- messages ----------------------------------------------------------------------------

    def _on_delivery(self, delivery: Delivery) -> None:
        if not self._take(delivery):
            self.dropped_unknown += self._pending.add(delivery, time.monotonic())

    def _take(self, delivery: Delivery) -> bool:
        """Record a delivery (or leave it out on purpose); False while it must be held."""
        if delivery.kind == Kind.DATA:
            return self._record_data(delivery)
        if self.services and delivery.kind in (Kind.REQUEST, Kind.RESPONSE):
            return self._record_service(delivery)
        return True

    def _resolve(self, delivery: Delivery, kinds: tuple[str, ...]) -> tuple[str, str, str] | None:
        assert self.participant is not None
        graph = self.participant.graph
        if graph.generation != self._generation:
            self._generation = graph.generation
            self._names = {}
            for node, endpoint in graph.endpoints():
                key = (topic_hash(endpoint.name), type_hash(endpoint.type))
                qos = endpoint.qos if endpoint.kind == PUBLISHER else {}
                if key not in self._names or qos:
                    self._names[key] = (endpoint.name, endpoint.type, endpoint.kind)
                del node
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
        self._write(name, topic, delivery, bytes(delivery.payload))
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
            channel_id = current.channels.get(name)
            if channel_id is None:
                channel_id = self._register(current, name, topic)
            current.writer.add_message(
                channel_id=channel_id, log_time=delivery.received, data=data,
                publish_time=delivery.stamp, sequence=topic.sequence + 1,
            )  # fmt: skip
        except OSError as err:  # a chunk went out and the disk refused it
            raise self._failed(current, err) from None
        topic.sequence += 1
        if self.max_bag_size:
            current.unchunked += MESSAGE_RECORD + len(data)
            if current.handle.tell() != current.position:  # the chunk went out with it
                current.chunk_written()
        topic.info.count += 1
        info = current.info
        info.count += 1
        info.start_ns = (
            delivery.received if info.count == 1 else min(info.start_ns, delivery.received)
        )
        info.end_ns = max(info.end_ns, delivery.received)

    def _register(self, current: _File, name: str, topic: _Topic) -> int:
        import yaml

        type_name = topic.info.type
        schema_id = current.schemas.get(type_name)
        if schema_id is None:
            schema_id = (
                current.writer.register_schema(type_name, topic.encoding, topic.text.encode())
                if topic.text
                else 0
            )
            current.schemas[type_name] = schema_id
        qos_text = yaml.safe_dump(topic.info.qos, sort_keys=False) if topic.info.qos else ""
        channel_id: int = current.writer.register_channel(
            name, "cdr", schema_id, {"offered_qos_profiles": qos_text}
        )
        current.channels[name] = channel_id
        return channel_id

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
        self._topics[name] = topic
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
                dict(_SUBSCRIPTION_QOS),
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


class _Held(NamedTuple):
    delivery: Delivery
    key: tuple[int, int]  # (topic hash, type hash)
    buffer: int  # id() of the buffer its payload keeps alive (alive while held: unique)


class _Pending:
    """Messages held until their topic (or its schema) is known, oldest first, bounded.

    A held payload is a view of the datagram it came in (or of a reassembled buffer) and keeps
    that whole buffer alive, so the byte bound counts each buffer once, whole, however many held
    messages share it (the messages of a coalesced datagram), plus ``HELD_OVERHEAD`` per
    message. Counting only each message's own bytes would let a sender keep one small message of
    each of many large batches (its stamps decide which are evicted first) and hold far more.

    When a new message does not fit, the oldest held messages are dropped first, whatever their
    topic. A topic about to be announced has its messages among the newest: they survive a
    flood of strangers' topics unless the flood alone outgrows the bound in the moment before
    the announcement, and nothing can keep them then. The other choices are worse: refusing
    new messages when full lets a flood that came first shut out the real topic until its
    entries age out; a per-topic share does not help, because a flood of random names gives
    every stranger a topic of its own while the real topic, with its several messages, is the
    biggest holder and would lose first.
    """

    def __init__(self, max_count: int, max_bytes: int) -> None:
        self.max_count = max_count
        self.max_bytes = max_bytes
        self.held: deque[_Held] = deque()
        self.since: dict[tuple[int, int], float] = {}  # only keys with messages held
        self.counts: dict[tuple[int, int], int] = {}
        self.buffers: dict[int, list[int]] = {}  # id -> [messages holding it, its size]
        self.bytes = 0  # the buffers counted once each, plus the overhead per message

    def __len__(self) -> int:
        return len(self.held)

    def add(self, delivery: Delivery, now: float) -> int:
        """Hold a message; return how many messages were dropped to bound the hold."""
        buffer, size = _retained(delivery.payload)
        if HELD_OVERHEAD + size > self.max_bytes:  # bigger than the whole hold
            return 1
        ident = id(buffer)
        dropped = 0
        while self.held and (
            len(self.held) >= self.max_count
            or self.bytes + HELD_OVERHEAD + (0 if ident in self.buffers else size) > self.max_bytes
        ):
            self._release(self.held.popleft())
            dropped += 1
        key = (delivery.topic, delivery.type)
        self.held.append(_Held(delivery, key, ident))
        self.since.setdefault(key, now)
        self.counts[key] = self.counts.get(key, 0) + 1
        holders = self.buffers.get(ident)
        if holders is None:
            self.buffers[ident] = [1, size]
            self.bytes += size
        else:
            holders[0] += 1
        self.bytes += HELD_OVERHEAD
        return dropped

    def retry(self, take: Callable[[Delivery], bool]) -> None:
        """Give every held message to ``take`` in order; keep those it refuses, in order."""
        for _ in range(len(self.held)):
            entry = self.held[0]
            if take(entry.delivery):
                self._release(self.held.popleft())
            else:
                self.held.rotate(-1)

    def expire(self, now: float, limit: float) -> int:
        """Drop the messages of topics held for more than ``limit`` seconds; return how many."""
        old = {key for key, since in self.since.items() if now - since > limit}
        if not old:
            return 0
        kept: deque[_Held] = deque()
        for entry in self.held:
            if entry.key in old:
                self._release(entry)
            else:
                kept.append(entry)
        dropped = len(self.held) - len(kept)
        self.held = kept
        return dropped

    def _release(self, entry: _Held) -> None:
        left = self.counts[entry.key] - 1
        if left:
            self.counts[entry.key] = left
        else:
            del self.counts[entry.key]
            del self.since[entry.key]
        holders = self.buffers[entry.buffer]
        holders[0] -= 1
        self.bytes -= HELD_OVERHEAD
        if not holders[0]:
            del self.buffers[entry.buffer]
            self.bytes -= holders[1]


def _retained(payload: memoryview | bytearray | mmap.mmap) -> tuple[object, int]:
    """The buffer a payload keeps alive, and its size in bytes."""
    if not isinstance(payload, memoryview):
        return payload, len(payload)
    base = payload.obj
    if isinstance(base, (bytes, bytearray, mmap.mmap)):
        return base, len(base)
    return (payload if base is None else base), payload.nbytes  # at least the view itself
