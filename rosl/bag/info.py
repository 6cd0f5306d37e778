"""``rosl bag info``: ROS 2 (Jazzy)'s layout, ``-v``, ``-t``, ``--sort`` and ``--json``.

Where a bag starts and ends, and how many messages each topic holds, is taken from the messages
its files hold, never from the totals a writer put in its MCAP Statistics record: those are
running figures the writer keeps, and one that takes a start time of 0 for "not set yet"
forgets a message logged at time 0 (a real bag's statistics started one message late). A
finished file's message indexes, one (log time, offset) pair per message written beside each
chunk, name every message's log time without decompressing a chunk, so they are what is read;
a chunk without them is read itself, and a file without a summary (its recorder was killed),
without chunk indexes, or whose indexes disagree with its statistics is read record by record;
a ``.db3`` file answers with SQL aggregates over its messages. The player takes its start and
length from the same :func:`extent`.

``-v`` adds what needs the messages themselves, so only ``-v`` reads them all: each topic's
size contribution (the sum of its serialized messages, as rosbag2 adds them up) and, for each
service, the requests and responses its events show (distinct client and sequence number).
"""

from __future__ import annotations

import datetime
import sys
from array import array
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, BinaryIO

from rosl.bag.errors import BagError
from rosl.bag.reader import damaged, has_summary, stream_records

if TYPE_CHECKING:
    from collections.abc import Collection, Iterable
    from pathlib import Path

    from rosl.bag.trim import Scan

LABEL = 19  # rosbag2: the longest label ("Topic information: ") is 19 columns
SERVICE_PAD = len("Service information: ")  # rosbag2 indents further service lines by 21
SORT_KEYS = ("name", "type", "count")
BOTH_FLAGS = (
    "Warning! You have set both the '-t' and '-v' parameters. The '-t' parameter will be ignored."
)
INFO_TYPE = "service_msgs/msg/ServiceEventInfo"  # how every service event starts (40 bytes)
_REQUEST_EVENTS = (0, 1)  # service_msgs/msg/ServiceEventInfo REQUEST_SENT, REQUEST_RECEIVED
_RESPONSE_EVENTS = (2, 3)  # RESPONSE_SENT, RESPONSE_RECEIVED


@dataclass(slots=True)
class Extent:
    """A bag's first and last log times and each topic's message count, from its messages."""

    start_ns: int = 0
    end_ns: int = 0
    counts: dict[str, int] = field(default_factory=dict)

    @property
    def count(self) -> int:
        """Messages in all."""
        return sum(self.counts.values())

    def add(self, topic: str, start: int, end: int, count: int) -> None:
        """Count ``count`` messages of ``topic`` logged between ``start`` and ``end``."""
        if not count:
            return
        first = not self.count
        self.start_ns = start if first else min(self.start_ns, start)
        self.end_ns = end if first else max(self.end_ns, end)
        self.counts[topic] = self.counts.get(topic, 0) + count

    def merge(self, other: Extent) -> None:
        """Add another file's messages."""
        for topic, count in other.counts.items():
            self.add(topic, other.start_ns, other.end_ns, count)


def extent(files: Iterable[Path]) -> Extent:
    """The messages the files really hold: their first and last log times, counts per topic.

    Raises:
        BagError: a file that cannot be read.
    """
    from rosl.bag import sqlite

    total = Extent()
    for path in files:
        if sqlite.is_db3(path):  # rosbag2's sqlite3 storage: SQL aggregates over its messages
            for topic in sqlite.summary(path).topics:
                total.add(topic.name, topic.start_ns, topic.end_ns, topic.count)
            continue
        try:
            with path.open("rb") as handle:
                found = _from_indexes(handle) if has_summary(path) else None
                if found is None:
                    handle.seek(0)
                    found = _from_records(handle)
        except OSError as err:
            raise BagError(f"cannot read {path}: {err.strerror}") from None
        except Exception as err:  # the mcap library's, zstd's or lz4's: a damaged file
            raise BagError(damaged(path, err)) from None
        total.merge(found)
    return total


def _from_indexes(handle: BinaryIO) -> Extent | None:
    from mcap.reader import make_reader

    summary = make_reader(handle).get_summary()
    if summary is None or not summary.chunk_indexes:
        return None
    topics = {channel_id: channel.topic for channel_id, channel in summary.channels.items()}
    found = Extent()
    for chunk in summary.chunk_indexes:
        if chunk.message_index_offsets:
            handle.seek(min(chunk.message_index_offsets.values()))
            times = _index_times(handle.read(chunk.message_index_length))
        else:
            times = _chunk_times(handle, chunk.chunk_start_offset)
        for channel_id, stamps in times.items():
            if channel_id in topics and stamps:
                found.add(topics[channel_id], min(stamps), max(stamps), len(stamps))
    stats = summary.statistics
    if stats is not None and stats.message_count != found.count:
        return None  # messages outside the indexed chunks, or indexes that miss some
    return found


def _index_times(block: bytes) -> dict[int, array[int]]:
    """Log times per channel id from a chunk's message index records."""
    times: dict[int, array[int]] = {}
    view, pos = memoryview(block), 0
    while pos + 9 <= len(view):
        opcode, length = view[pos], int.from_bytes(view[pos + 1 : pos + 9], "little")
        body, pos = view[pos + 9 : pos + 9 + length], pos + 9 + length
        if opcode != 0x07 or len(body) < 6:  # not a MessageIndex record
            continue
        entries = array("Q")
        size = int.from_bytes(body[2:6], "little")
        entries.frombytes(body[6 : 6 + size - size % 16])
        if sys.byteorder == "big":
            entries.byteswap()
        times.setdefault(int.from_bytes(body[:2], "little"), array("Q")).extend(entries[0::2])
    return times


def _chunk_times(handle: BinaryIO, offset: int) -> dict[int, array[int]]:
    from mcap.data_stream import ReadDataStream
    from mcap.records import Chunk, Message
    from mcap.stream_reader import breakup_chunk

    handle.seek(offset + 9)  # past the chunk record's opcode and length
    times: dict[int, array[int]] = {}
    for record in breakup_chunk(Chunk.read(ReadDataStream(handle))):
        if isinstance(record, Message):
            times.setdefault(record.channel_id, array("Q")).append(record.log_time)
    return times


def _from_records(handle: BinaryIO) -> Extent:
    from mcap.records import Channel, Message

    topics: dict[int, str] = {}
    times: dict[str, array[int]] = {}
    for record in stream_records(handle):
        if isinstance(record, Channel):
            topics[record.id] = record.topic
        elif isinstance(record, Message) and record.channel_id in topics:
            times.setdefault(topics[record.channel_id], array("Q")).append(record.log_time)
    found = Extent()
    for topic, stamps in times.items():
        found.add(topic, min(stamps), max(stamps), len(stamps))
    return found


def refuse_foreign_encodings(found: Scan, topics: Collection[str] | None = None) -> None:
    """Refuse a bag (or the chosen ``topics`` of it) whose messages are not CDR, as rosbag2 does.

    Raises:
        BagError: a channel with another message encoding (``json``, ``protobuf``, ...).
    """
    for name in sorted(found.channels):
        encoding = found.channels[name].message_encoding
        if encoding != "cdr" and (topics is None or name in topics):
            raise BagError(f"Could not find converter for format {encoding} (topic {name})")


def is_service_event(name: str, type_name: str) -> bool:
    """Whether a topic carries a service's events (rosbag2's test: its name and its type)."""
    return (
        name.endswith("/_service_event") and "/srv/" in type_name and type_name.endswith("_Event")
    )


def summary(target: Path, *, verbose: bool = False, sort: str = "name") -> dict[str, Any]:
    """What ``info`` reports, as plain data, topics and services in ``sort`` order.

    Raises:
        BagError: the bag cannot be read, holds messages that are not CDR, or ``sort`` is
            not one of name, type, count.
    """
    from rosl.bag.trim import scan

    sort = _sort_key(sort)
    found = scan(target)
    refuse_foreign_encodings(found)
    span = extent(found.files)
    entries = {
        name: (channel.type, span.counts.get(name, 0), channel.message_encoding)
        for name, channel in found.channels.items()
    }
    listed = _listed(found.info)
    entries = {n: e for n, e in entries.items() if e[1] or n in listed}
    for name, (type_name, encoding) in listed.items():
        entries.setdefault(name, (type_name, 0, encoding))
    sizes, calls = _traffic(target, entries) if verbose else ({}, {})
    topics, services = [], []
    for name, (type_name, count, encoding) in sorted(entries.items()):
        item: dict[str, Any] = {"name": name, "type": type_name}
        if is_service_event(name, type_name):
            item = {"name": name.removesuffix("/_service_event"),
                    "type": type_name.removesuffix("_Event"), "event_count": count}  # fmt: skip
            if verbose:
                item["request_count"], item["response_count"] = calls.get(name, (0, 0))
            services.append(item)
        else:
            item["count"] = count
            topics.append(item)
        item["serialization_format"] = encoding or "cdr"
        if verbose:
            item["size"] = sizes.get(name, 0)
    return {
        "files": [p.name for p in found.files],
        "unfinished": [p.name for p in found.files if not has_summary(p)],
        "bag_size": sum(p.stat().st_size for p in found.files),
        "storage_id": _storage_id(found.files),
        "ros_distro": (found.info or {}).get("ros_distro", "") or "",
        "duration_ns": span.end_ns - span.start_ns,
        "start_ns": span.start_ns,
        "end_ns": span.end_ns,
        "messages": sum(t["count"] for t in topics),
        "topics": _sorted(topics, sort, lambda t: t["count"]),
        "services": _sorted(services, sort, _calls if verbose else lambda s: s["event_count"]),
    }


def _calls(service: dict[str, Any]) -> int:
    """What ``--sort count`` compares for a service under ``-v``: requests plus responses."""
    return int(service["request_count"] + service["response_count"])


def _storage_id(files: list[Path]) -> str:
    from rosl.bag import sqlite

    return "sqlite3" if files and all(sqlite.is_db3(p) for p in files) else "mcap"


def _sort_key(sort: str) -> str:
    key = sort.lower()  # rosbag2 lowers the word before looking it up
    if key not in SORT_KEYS:
        raise BagError(f"--sort '{sort}' is not one of {', '.join(SORT_KEYS)}")
    return key


def _sorted(items: list[dict[str, Any]], sort: str, count: Any) -> list[dict[str, Any]]:
    """Ascending by name, type or count as rosbag2 sorts (ties stay in name order)."""
    keys = {"name": lambda i: i["name"], "type": lambda i: i["type"], "count": count}
    return sorted(items, key=keys[sort])


def _listed(info: dict[str, Any] | None) -> dict[str, tuple[str, str]]:
    """Topics metadata.yaml lists: ROS 2 shows them all, Count: 0 when nothing came."""
    listed = {}
    for entry in (info or {}).get("topics_with_message_count") or []:
        topic = entry.get("topic_metadata") or {}
        if topic.get("name"):
            listed[str(topic["name"])] = (
                str(topic.get("type", "")),
                str(topic.get("serialization_format", "") or "cdr"),
            )
    return listed


def _traffic(
    target: Path, entries: dict[str, tuple[str, int, str]]
) -> tuple[dict[str, int], dict[str, tuple[int, int]]]:
    """Bytes per topic, and (requests, responses) per service event topic, from every message."""
    from mcap.exceptions import McapError

    from rosl.bag.reader import iter_bag
    from rosl.idl import registry
    from rosl.idl.errors import InterfaceError

    sizes: dict[str, int] = {}
    seen: dict[str, tuple[set[tuple[bytes, int]], set[tuple[bytes, int]]]] = {
        name: (set(), set()) for name, entry in entries.items() if is_service_event(name, entry[0])
    }
    if seen:
        registry.get_message_class(INFO_TYPE)
    store = registry.store()
    try:
        for message in iter_bag(target):
            sizes[message.topic] = sizes.get(message.topic, 0) + len(message.data)
            if message.topic not in seen:
                continue
            try:  # the event starts with its ServiceEventInfo: read only that
                event: Any = store.deserialize(message.data[:44], INFO_TYPE)
            except InterfaceError as err:
                raise BagError(f"cannot read a service event of {message.topic}: {err}") from None
            call = (bytes(event.client_gid), int(event.sequence_number))
            requests, responses = seen[message.topic]
            if event.event_type in _REQUEST_EVENTS:
                requests.add(call)
            elif event.event_type in _RESPONSE_EVENTS:
                responses.add(call)
    except McapError as err:
        raise BagError(f"cannot read {target}: {err}") from None
    return sizes, {name: (len(req), len(resp)) for name, (req, resp) in seen.items()}


def _size(size: int) -> str:
    units = ["B", "KiB", "MiB", "GiB", "TiB"]
    value = float(size)
    unit = 0
    while value >= 1024 and unit < len(units) - 1:
        value /= 1024
        unit += 1
    return f"{int(value)} B" if unit == 0 else f"{value:.1f} {units[unit]}"


def _stamp(ns: int) -> str:
    seconds, nanos = divmod(ns, 1_000_000_000)
    moment = datetime.datetime.fromtimestamp(seconds)
    return f"{moment.strftime('%b %e %Y %H:%M:%S')}.{nanos:09d} ({seconds}.{nanos:09d})"


def text(data: dict[str, Any]) -> str:
    """ROS 2's ``bag info`` text for a :func:`summary` (``-v``'s when it holds sizes)."""
    verbose = any("size" in item for item in data["topics"] + data["services"])

    def row(label: str, value: str) -> str:
        return f"{label:<{LABEL}}{value}"

    def extra(item: dict[str, Any]) -> str:
        return f"Size Contribution: {_size(item['size'])} | " if verbose else ""

    seconds, nanos = divmod(data["duration_ns"], 1_000_000_000)
    lines = [
        "",
        row("Files:", data["files"][0] if data["files"] else ""),
        *[" " * LABEL + name for name in data["files"][1:]],
        row("Bag size:", _size(data["bag_size"])),
        row("Storage id:", data["storage_id"]),
        row("ROS Distro:", data["ros_distro"] or "unknown"),  # as rosbag2 prints an unnamed one
        row("Duration:", f"{seconds}.{nanos:09d}s"),
        row("Start:", _stamp(data["start_ns"])),
        row("End:", _stamp(data["end_ns"])),
        row("Messages:", str(data["messages"])),
    ]
    topics = [
        f"Topic: {t['name']} | Type: {t['type']} | Count: {t['count']} | {extra(t)}"
        f"Serialization Format: {t['serialization_format']}"
        for t in data["topics"]
    ]
    lines.append(row("Topic information:", topics[0] if topics else ""))
    lines += [" " * LABEL + line for line in topics[1:]]

    def counts(service: dict[str, Any]) -> str:
        if not verbose:
            return f"Event Count: {service['event_count']}"
        return (
            f"Request Count: {service['request_count']} | "
            f"Response Count: {service['response_count']}"
        )

    services = [
        f"Service: {s['name']} | Type: {s['type']} | {counts(s)} | {extra(s)}"
        f"Serialization Format: {s['serialization_format']}"
        for s in data["services"]
    ]
    lines.append(row("Service:", str(len(services))))
    lines.append("Service information: " + (services[0] if services else ""))
    lines += [" " * SERVICE_PAD + line for line in services[1:]]
    if services:
        lines.append("")  # rosbag2 ends each service line and then the whole text
    if data["unfinished"]:
        lines.append(
            f"(unfinished: {', '.join(data['unfinished'])}; run `rosl bag reindex` to repair)"
        )
    return "\n".join(lines) + "\n"
