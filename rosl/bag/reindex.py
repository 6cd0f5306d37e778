"""``rosl bag reindex``: make a folder whole again after a crash.

Every ``*.mcap`` file is checked to be MCAP before anything is touched. Each unfinished file
(no footer: its recorder was killed) is read up to the last complete record and rewritten with
its index and summary, its chunk compression and its channels' metadata (the
``offered_qos_profiles``) kept; the rewrite goes to a temporary file that replaces the original
only once it is complete, so a failed write leaves the original as it was. Then
``metadata.yaml`` is rebuilt from the files present in split order (``_2`` before ``_10``),
each topic with the QoS its channel carries and the RIHS01 hash of the schema the file holds;
topics the old ``metadata.yaml`` listed but no file holds stay, with count 0. Finished files
are left as they are.
"""

from __future__ import annotations

import contextlib
import os
from typing import TYPE_CHECKING, Any, BinaryIO

from rosl.bag import metadata
from rosl.bag.errors import BagError
from rosl.bag.reader import (
    bag_files,
    check_magic,
    has_summary,
    iter_file,
    iter_records,
    split_order,
)

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.bag.reader import BagMessage

CHUNK_SIZE = 4 * 1024 * 1024


def rewrite(path: Path) -> int:
    """Rewrite an unfinished MCAP file completely; return how many messages it kept.

    Raises:
        BagError: the new file cannot be written (disk full, ...); the original is left
            untouched and the partial copy removed.
    """
    temporary = path.with_name(path.name + ".reindex")
    try:
        with path.open("rb") as source, temporary.open("wb") as target:
            count = _copy(source, target)
            target.flush()
            os.fsync(target.fileno())
        temporary.replace(path)
    except OSError as err:
        with contextlib.suppress(OSError):
            temporary.unlink(missing_ok=True)
        reason = err.strerror or type(err).__name__
        raise BagError(f"cannot rewrite {path}: {reason} (the file was left as it was)") from None
    return count


def _copy(source: BinaryIO, target: BinaryIO) -> int:
    """Write the complete records of ``source`` to ``target`` as a finished MCAP file."""
    from mcap.writer import Writer

    writer = Writer(target, compression=_compression(source), chunk_size=CHUNK_SIZE)
    source.seek(0)
    writer.start(profile="ros2", library="rosl reindex")
    schemas: dict[str, int] = {}
    channels: dict[str, int] = {}
    count = 0
    for message in iter_records(source):
        if message.type not in schemas:
            text = message.schema_text.encode()
            schemas[message.type] = (
                writer.register_schema(message.type, message.schema_encoding, text)
                if message.schema_encoding
                else 0
            )
        if message.topic not in channels:
            channels[message.topic] = writer.register_channel(  # offered QoS kept
                message.topic, "cdr", schemas[message.type], dict(message.channel_metadata)
            )
        writer.add_message(
            channels[message.topic], message.log_time, message.data, message.publish_time,
            message.sequence,
        )  # fmt: skip
        count += 1
    writer.finish()
    return count


def _compression(source: BinaryIO) -> Any:
    """The compression of the file's first chunk (none when it holds no complete chunk)."""
    from mcap.records import Chunk
    from mcap.stream_reader import StreamReader
    from mcap.writer import CompressionType

    kinds = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4}
    with contextlib.suppress(Exception):  # the torn end of an unfinished file
        for record in StreamReader(source, skip_magic=False, emit_chunks=True).records:
            if isinstance(record, Chunk):
                return kinds.get(record.compression, CompressionType.NONE)
    return CompressionType.NONE


def reindex(folder: Path) -> list[str]:
    """Repair a recording folder; return a line per file and one for the metadata.

    Raises:
        BagError: not a folder, no .mcap files in it, a file that is not MCAP (nothing is
            changed then), or a file that cannot be rewritten.
    """
    if not folder.is_dir():
        raise BagError(f"'{folder}' is not a recording folder")
    files = split_order(folder.glob("*.mcap"))
    if not files:
        raise BagError(f"'{folder}' holds no .mcap files to reindex")
    for path in files:  # before anything is rewritten
        check_magic(path)
    previous = _previous_topics(folder)
    lines = []
    for path in files:
        if has_summary(path):
            lines.append(f"{path.name}: complete")
        else:
            kept = rewrite(path)
            lines.append(f"{path.name}: was unfinished; rewritten with {kept} messages")
    topics: dict[str, metadata.TopicInfo] = {}
    infos = [_count(path, topics, previous) for path in files]
    for name, old in previous.items():  # listed before, but no message on disk: count 0
        if name not in topics:
            qos = old.get("offered_qos_profiles")
            topics[name] = metadata.TopicInfo(
                name, str(old.get("type", "")), qos=list(qos) if isinstance(qos, list) else [],
                type_hash=str(old.get("type_description_hash") or ""),
            )  # fmt: skip
    metadata.write(folder, list(topics.values()), infos)
    lines.append(
        f"metadata.yaml: {sum(t.count for t in topics.values())} messages on {len(topics)} topics"
    )
    return lines


def _previous_topics(folder: Path) -> dict[str, dict[str, Any]]:
    """The topics an existing (readable) ``metadata.yaml`` lists, by name."""
    if not (folder / "metadata.yaml").is_file():
        return {}
    try:
        listed = metadata.read(folder).get("topics_with_message_count") or []
    except BagError:
        return {}
    return {e["topic_metadata"]["name"]: e["topic_metadata"] for e in listed}


def _count(
    path: Path, topics: dict[str, metadata.TopicInfo], previous: dict[str, dict[str, Any]]
) -> metadata.FileInfo:
    """Count one file's messages into ``topics``; its entry for metadata.yaml."""
    info = metadata.FileInfo(path.name)
    for message in iter_file(path):
        topic = topics.get(message.topic)
        if topic is None:
            old = previous.get(message.topic, {})
            # the QoS the file's channel carries: readers (rosbags) match the topics of
            # metadata.yaml with the channels by name, type and QoS
            topic = topics[message.topic] = metadata.TopicInfo(
                message.topic, message.type,
                qos=metadata.offered_qos(message.channel_metadata),
                type_hash=old.get("type_description_hash") or _hash(message),
            )  # fmt: skip
        topic.count += 1
        info.count += 1
        info.start_ns = (
            message.log_time if info.count == 1 else min(info.start_ns, message.log_time)
        )
        info.end_ns = max(info.end_ns, message.log_time)
    return info


def _hash(message: BagMessage) -> str:
    """The RIHS01 hash of a message's type: from the file's schema, else this process's type."""
    from rosl.idl import registry
    from rosl.idl.errors import InterfaceError

    if message.schema_encoding and message.schema_text:
        with contextlib.suppress(InterfaceError):
            return registry.store().schema_type_hash(
                message.type, message.schema_encoding, message.schema_text
            )
    try:
        registry.get_message_class(message.type)
        return registry.store().type_hash(message.type)
    except InterfaceError:
        return ""


def check(target: Path) -> None:
    """Raise a BagError that points at reindex when a bag has an unfinished file."""
    files, _ = bag_files(target)
    for path in files:
        if not has_summary(path):
            raise BagError(
                f"{path} is unfinished (its recorder stopped abruptly); run "
                f"`rosl bag reindex {path.parent}` to repair it"
            )
