"""Reading recordings: a rosbag2 folder, a folder of MCAP files, one MCAP file.

A file without its summary (a recorder that was killed) is read record by record up to the
last complete one, and said so; ``rosl bag reindex`` rewrites it whole.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, BinaryIO

from rosl.bag import metadata
from rosl.bag.errors import BagError

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

MAGIC = b"\x89MCAP0\r\n"


@dataclass(frozen=True, slots=True)
class BagMessage:
    """One recorded message."""

    topic: str
    type: str
    log_time: int
    publish_time: int
    sequence: int
    data: bytes
    schema_encoding: str = ""
    schema_text: str = ""
    channel_metadata: dict[str, str] = field(default_factory=dict)  # offered_qos_profiles


@dataclass(slots=True)
class Channel:
    """One channel (topic) of a bag."""

    topic: str
    type: str
    schema_encoding: str
    schema_text: str
    count: int = 0
    qos: list[dict[str, Any]] = field(default_factory=list)
    type_hash: str = ""


def bag_files(target: Path) -> tuple[list[Path], dict[str, Any] | None]:
    """The MCAP files of a bag (folder or file) and its metadata, if any.

    Raises:
        BagError: missing target, no MCAP files, metadata naming missing files, not MCAP.
    """
    if not target.exists():
        raise BagError(f"no recording at '{target}'")
    if target.is_file():
        _check_magic(target)
        return [target], None
    if (target / "metadata.yaml").is_file():
        info = metadata.read(target)
        files = [target / name for name in info["relative_file_paths"]]
        missing = [str(p.name) for p in files if not p.is_file()]
        if missing:
            raise BagError(
                f"{target / 'metadata.yaml'} names files that are not there: {', '.join(missing)} "
                f"(run `rosl bag reindex {target}` to rebuild it from the .mcap files present)"
            )
    else:
        info = None
        files = sorted(target.glob("*.mcap"))
        if not files:
            raise BagError(f"'{target}' holds no metadata.yaml and no .mcap files")
    for path in files:
        _check_magic(path)
    return files, info


def _check_magic(path: Path) -> None:
    try:
        with path.open("rb") as handle:
            head = handle.read(len(MAGIC))
    except OSError as err:
        raise BagError(f"cannot read {path}: {err.strerror}") from None
    if head != MAGIC:
        raise BagError(f"{path} is not an MCAP file (it does not start with the MCAP magic)")


def has_summary(path: Path) -> bool:
    """Whether an MCAP file ends with its footer (was finished properly)."""
    with path.open("rb") as handle:
        handle.seek(0, 2)
        size = handle.tell()
        if size < 2 * len(MAGIC):
            return False
        handle.seek(size - len(MAGIC))
        return handle.read(len(MAGIC)) == MAGIC


def iter_file(path: Path, topics: set[str] | None = None) -> Iterator[BagMessage]:
    """Messages of one MCAP file in log-time order (stream order when it is unfinished)."""
    from mcap.exceptions import McapError

    with path.open("rb") as handle:
        try:
            if has_summary(path):
                yield from _iter_indexed(handle, topics)
                return
        except McapError:
            handle.seek(0)
        yield from iter_records(handle, topics)


def _iter_indexed(handle: BinaryIO, topics: set[str] | None) -> Iterator[BagMessage]:
    from mcap.reader import make_reader

    reader = make_reader(handle)
    for schema, channel, message in reader.iter_messages(topics=list(topics) if topics else None):
        yield BagMessage(
            channel.topic,
            schema.name if schema else "",
            message.log_time,
            message.publish_time,
            message.sequence,
            bytes(message.data),
            schema.encoding if schema else "",
            schema.data.decode(errors="replace") if schema else "",
            channel.metadata,
        )


def iter_records(handle: BinaryIO, topics: set[str] | None = None) -> Iterator[BagMessage]:
    """Messages of an MCAP stream read record by record, stopping at a torn tail."""
    from mcap.exceptions import McapError
    from mcap.records import Channel as McapChannel
    from mcap.records import Message, Schema
    from mcap.stream_reader import StreamReader

    schemas: dict[int, Any] = {}
    channels: dict[int, Any] = {}
    records = StreamReader(handle, skip_magic=False, emit_chunks=False).records
    while True:
        try:
            record = next(records)
        except StopIteration:
            return
        except (McapError, EOFError, ValueError, KeyError, OSError, Exception):
            return  # the torn end of an unfinished file
        if isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, McapChannel):
            channels[record.id] = record
        elif isinstance(record, Message):
            channel = channels.get(record.channel_id)
            if channel is None or (topics and channel.topic not in topics):
                continue
            schema = schemas.get(channel.schema_id)
            yield BagMessage(
                channel.topic, schema.name if schema else "", record.log_time,
                record.publish_time, record.sequence, bytes(record.data),
                schema.encoding if schema else "",
                schema.data.decode(errors="replace") if schema else "", channel.metadata,
            )  # fmt: skip


def iter_bag(target: Path, topics: set[str] | None = None) -> Iterator[BagMessage]:
    """Every message of a bag, file by file, in log-time order within each file."""
    files, _ = bag_files(target)
    for path in files:
        yield from iter_file(path, topics)


def channels(target: Path) -> dict[str, Channel]:
    """The topics of a bag with their types, schemas and counts (from summaries if present)."""
    files, info = bag_files(target)
    found: dict[str, Channel] = {}
    for path in files:
        for message in iter_file(path):
            channel = found.get(message.topic)
            if channel is None:
                channel = found[message.topic] = Channel(
                    message.topic, message.type, message.schema_encoding, message.schema_text
                )
            channel.count += 1
    if info is not None:
        for entry in info.get("topics_with_message_count", []):
            meta = entry["topic_metadata"]
            channel = found.get(meta["name"])
            if channel is not None:
                channel.qos = list(meta.get("offered_qos_profiles") or [])
                channel.type_hash = meta.get("type_description_hash", "")
    return found
