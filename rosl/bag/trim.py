"""``rosl bag filter`` and ``convert``: a new rosbag2 folder holding a selection of a bag.

Messages are copied untouched — payload bytes, log and publish times, sequence numbers — with
their schemas and channel metadata (the ``offered_qos_profiles`` the recorder wrote), into one
MCAP file plus ``metadata.yaml``. A selection is a set of topics, an exclusion pattern and a
time window in seconds from the bag's first message; ``convert`` selects everything and only
changes the chunk compression. :func:`scan` (the bag's channel table) is shared with the player.
"""

from __future__ import annotations

import contextlib
import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, BinaryIO

from rosl.bag import metadata, sqlite
from rosl.bag.errors import BagError
from rosl.bag.info import extent, refuse_foreign_encodings
from rosl.bag.reader import bag_files, has_summary, iter_bag, stream_records
from rosl.bag.writer import BagFile

if TYPE_CHECKING:
    from pathlib import Path


NS = 1_000_000_000
COMPRESSIONS = ("zstd", "lz4", "none")


@dataclass(slots=True)
class SourceChannel:
    """One topic of a bag as its MCAP channel and schema records describe it."""

    topic: str
    type: str
    schema_encoding: str
    schema_data: bytes
    message_encoding: str = "cdr"
    metadata: dict[str, str] = field(default_factory=dict)
    count: int = 0

    def offered_qos(self) -> list[dict[str, Any]]:
        """The ``offered_qos_profiles`` the recorder wrote in the channel's metadata."""
        return metadata.offered_qos(self.metadata)


@dataclass(slots=True)
class Scan:
    """What a bag holds, read from its summaries (streamed for unfinished files)."""

    channels: dict[str, SourceChannel]
    start_ns: int
    end_ns: int
    count: int
    unfinished: list[Path]
    info: dict[str, Any] | None
    compression: str = ""
    files: list[Path] = field(default_factory=list)


@dataclass(slots=True)
class CopyResult:
    """What ``filter``/``convert`` wrote, and the warnings met on the way."""

    folder: Path
    written: dict[str, int]
    total: int
    compression: str
    warnings: list[str] = field(default_factory=list)

    def summary(self) -> str:
        """One line: what went where."""
        count = sum(self.written.values())
        return (
            f"wrote {count} of {self.total} messages on {len(self.written)} topics to "
            f"'{self.folder}' ({self.compression or 'uncompressed'})"
        )


def unfinished_warning(path: Path) -> str:
    """The one-line warning for a file whose recorder was killed."""
    return (
        f"warning: {path} is unfinished (its recorder stopped abruptly); using its complete "
        f"records only — run `rosl bag reindex {path.parent}` to repair it"
    )


def scan(target: Path) -> Scan:
    """The channels, time span and message count of a bag (folder or file).

    Raises:
        BagError: from :func:`rosl.bag.reader.bag_files`, or a file the MCAP reader rejects.
    """
    from mcap.exceptions import McapError

    files, info = bag_files(target)
    found = Scan({}, 0, 0, 0, [], info, files=files)
    for path in files:
        if sqlite.is_db3(path):
            _scan_db3(path, found)
            continue
        try:
            with path.open("rb") as handle:
                finished = has_summary(path)
                if not (finished and _scan_summary(handle, found)):
                    if not finished:  # a finished file may just lack its Statistics record
                        found.unfinished.append(path)
                    handle.seek(0)
                    _scan_records(handle, found)
        except (McapError, OSError, ValueError) as err:
            raise BagError(f"cannot read {path}: {err}") from None
    return found


def _scan_db3(path: Path, found: Scan) -> None:
    """Add a ``.db3`` file's topics, counts and time span (SQL aggregates, no payloads)."""
    held = sqlite.summary(path)
    for topic in held.topics:
        entry = found.channels.get(topic.name)
        if entry is None:
            entry = found.channels[topic.name] = SourceChannel(
                topic.name, topic.type, topic.schema_encoding, topic.schema_text.encode(),
                topic.serialization_format, topic.channel_metadata(),
            )  # fmt: skip
        entry.count += topic.count
    _span(found, held.start_ns, held.end_ns, held.count)


def _channel(found: Scan, channel: Any, schema: Any) -> SourceChannel:
    entry = found.channels.get(channel.topic)
    if entry is None:
        entry = found.channels[channel.topic] = SourceChannel(
            channel.topic, schema.name if schema else "", schema.encoding if schema else "",
            bytes(schema.data) if schema else b"", channel.message_encoding,
            dict(channel.metadata),
        )  # fmt: skip
    return entry


def _span(found: Scan, start: int, end: int, count: int) -> None:
    if not count:
        return
    found.start_ns = start if not found.count else min(found.start_ns, start)
    found.end_ns = max(found.end_ns, end)
    found.count += count


def _scan_summary(handle: BinaryIO, found: Scan) -> bool:
    from mcap.reader import make_reader

    summary = make_reader(handle).get_summary()
    if summary is None or summary.statistics is None:
        return False
    stats = summary.statistics
    for channel_id, channel in summary.channels.items():
        entry = _channel(found, channel, summary.schemas.get(channel.schema_id))
        entry.count += stats.channel_message_counts.get(channel_id, 0)
    _span(found, stats.message_start_time, stats.message_end_time, stats.message_count)
    if summary.chunk_indexes and not found.compression:
        found.compression = summary.chunk_indexes[0].compression
    return True


def _scan_records(handle: BinaryIO, found: Scan) -> None:
    from mcap.records import Channel, Message, Schema

    schemas: dict[int, Any] = {}
    channels: dict[int, SourceChannel] = {}
    start, end, count = 0, 0, 0
    for record in stream_records(handle):
        if isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, Channel):
            channels[record.id] = _channel(found, record, schemas.get(record.schema_id))
        elif isinstance(record, Message) and record.channel_id in channels:
            channels[record.channel_id].count += 1
            start = record.log_time if not count else min(start, record.log_time)
            end = max(end, record.log_time)
            count += 1
    _span(found, start, end, count)


def copy(
    source: Path,
    output: Path,
    *,
    topics: list[str] | None = None,
    exclude: str | None = None,
    start: float | None = None,
    end: float | None = None,
    compression: str | None = None,
    ros_distro: str | None = None,
    storage: str = "mcap",
) -> CopyResult:
    """Write the selected messages of ``source`` to a new rosbag2 folder ``output``.

    Every selected topic of the source's channels gets its channel and its entry in
    ``metadata.yaml``, also when no message of it falls in the window.

    Args:
        source: a bag folder or MCAP file.
        output: the folder to create (must not exist, or be empty).
        topics: keep only these topics (all when None).
        exclude: drop topics matching this regular expression.
        start: drop messages earlier than this many seconds after the bag's first message.
        end: drop messages later than this many seconds after the bag's first message.
        compression: ``zstd``, ``lz4`` or ``none``; None keeps the source's.
        ros_distro: the layout of the new bag's metadata; None keeps the source's label.
        storage: ``mcap`` (one MCAP file) or ``sqlite3`` (one ``.db3`` file, uncompressed).

    Raises:
        BagError: unreadable source, bad pattern or window, output not writable.
    """
    found = scan(source)
    label = metadata.distro(ros_distro) if ros_distro else metadata.labelled(found.info)
    pattern = _pattern(exclude)
    wanted = sorted(
        name
        for name in found.channels
        if (topics is None or name in topics) and not (pattern and pattern.search(name))
    )
    refuse_foreign_encodings(found, set(wanted))
    first = found.start_ns
    if start is not None or end is not None:  # the first message held, not what Statistics say
        first = extent(found.files).start_ns
    low = first + round(start * NS) if start is not None else 0
    high = first + round(end * NS) if end is not None else 2**64
    if high < low:
        raise BagError(f"--end {end} is before --start {start}")
    if storage not in ("mcap", sqlite.STORAGE):
        raise BagError(f"unknown storage '{storage}' (mcap or {sqlite.STORAGE})")
    if storage == sqlite.STORAGE and compression not in (None, "none"):
        raise BagError(f"{sqlite.STORAGE} bags are written uncompressed (no --compression-format)")
    chosen = (found.compression or "none") if compression is None else compression
    if storage == sqlite.STORAGE:
        chosen = "none"
    result = CopyResult(output, {}, found.count, "" if chosen == "none" else chosen)
    result.warnings = [unfinished_warning(p) for p in found.unfinished]
    result.warnings += [f"warning: topic {t} is not in {source}" for t in topics or () if
                        t not in found.channels]  # fmt: skip
    created = _prepare(source, output)
    infos = _topic_infos(found, wanted)
    try:
        out: BagFile | sqlite.Db3File = (
            sqlite.Db3File(output / f"{output.name}_0{sqlite.SUFFIX}", label)
            if storage == sqlite.STORAGE
            else BagFile(
                output / f"{output.name}_0.mcap", compression=chosen, library="rosl bag filter",
                version=metadata.VERSIONS[label],
            )
        )  # fmt: skip
    except BaseException:
        _unprepare(output, created)
        raise
    try:
        ids = {
            info.name: out.channel(
                info, found.channels[info.name].schema_encoding,
                found.channels[info.name].schema_data,
            )
            for info in infos
        }  # fmt: skip
        messages = iter_bag(source, set(wanted)) if wanted else iter(())
        for message in (m for m in messages if low <= m.log_time <= high):
            out.write(
                ids[message.topic], message.log_time, message.publish_time, message.sequence,
                message.data,
            )  # fmt: skip
            result.written[message.topic] = result.written.get(message.topic, 0) + 1
        for info in infos:
            info.count = result.written.get(info.name, 0)
        custom = _custom(found)
        out.finish(
            metadata.information(
                infos, [out.info], custom=custom, ros_distro=label, storage=storage
            ),
            label,
        )
    except BaseException:  # nothing half-written is left: the folder is as it was
        out.abandon()
        out.path.unlink(missing_ok=True)
        _unprepare(output, created)
        raise
    metadata.write(output, infos, [out.info], custom, ros_distro=label, storage=storage)
    return result


def _pattern(exclude: str | None) -> re.Pattern[str] | None:
    if exclude is None:
        return None
    try:
        return re.compile(exclude)
    except re.error as err:
        raise BagError(f"--exclude '{exclude}' is not a regular expression: {err}") from None


def _prepare(source: Path, output: Path) -> bool:
    """Make the (empty) output folder; whether it was made here."""
    inside = source.is_dir() and output.resolve().is_relative_to(source.resolve())
    if inside or source.resolve().is_relative_to(output.resolve()):
        raise BagError(f"the output folder '{output}' would overwrite the input '{source}'")
    if output.exists() and (not output.is_dir() or any(output.iterdir())):
        raise BagError(f"Output folder '{output}' already exists and is not empty")
    created = not output.exists()
    try:
        output.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise BagError(f"cannot create '{output}': {err.strerror}") from None
    return created


def _unprepare(output: Path, created: bool) -> None:
    """Remove the output folder again when it was made here (and is empty)."""
    if created:
        with contextlib.suppress(OSError):
            output.rmdir()


def _topic_infos(found: Scan, names: list[str]) -> list[metadata.TopicInfo]:
    """The new bag's topics: QoS and type hash as the source's metadata or channels say."""
    previous = {
        e["topic_metadata"]["name"]: e["topic_metadata"]
        for e in (found.info or {}).get("topics_with_message_count") or []
    }
    infos = []
    for name in names:
        channel = found.channels[name]
        old = previous.get(name, {})
        qos = metadata.parse_profiles(old.get("offered_qos_profiles")) or channel.offered_qos()
        type_hash = (
            channel.metadata.get("topic_type_hash")
            or str(old.get("type_description_hash") or "")
            or _hash(channel.type)
        )
        infos.append(
            metadata.TopicInfo(
                name, channel.type, channel.message_encoding, qos=qos, type_hash=type_hash
            )
        )
    return infos


def _hash(type_name: str) -> str:
    from rosl.idl import registry
    from rosl.idl.errors import InterfaceError

    try:
        registry.get_message_class(type_name)
        return registry.store().type_hash(type_name)
    except InterfaceError:
        return ""


def _custom(found: Scan) -> dict[str, str]:
    custom = (found.info or {}).get("custom_data") or {}
    return {str(k): str(v) for k, v in custom.items()} if isinstance(custom, dict) else {}
