"""``rosl bag reindex``: make a folder whole again after a crash.

Each unfinished MCAP file (no footer: its recorder was killed) is read up to the last
complete record and rewritten with its index and summary, its channels' metadata (the
``offered_qos_profiles``) kept; then ``metadata.yaml`` is rebuilt from the files present, each
topic with the QoS its channel carries. Finished files are left as they are.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from rosl.bag import metadata
from rosl.bag.errors import BagError
from rosl.bag.reader import bag_files, has_summary, iter_file, iter_records

if TYPE_CHECKING:
    from pathlib import Path


def rewrite(path: Path) -> int:
    """Rewrite an unfinished MCAP file completely; return how many messages it kept."""
    from mcap.writer import CompressionType, Writer

    temporary = path.with_suffix(".mcap.reindex")
    count = 0
    with path.open("rb") as source, temporary.open("wb") as target:
        writer = Writer(target, compression=CompressionType.NONE)
        writer.start(profile="ros2", library="rosl reindex")
        schemas: dict[str, int] = {}
        channels: dict[str, int] = {}
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
        target.flush()
        os.fsync(target.fileno())
    temporary.replace(path)
    return count


def reindex(folder: Path) -> list[str]:
    """Repair a recording folder; return a line per file and one for the metadata.

    Raises:
        BagError: not a folder, or no .mcap files in it.
    """
    if not folder.is_dir():
        raise BagError(f"'{folder}' is not a recording folder")
    files = sorted(folder.glob("*.mcap"))
    if not files:
        raise BagError(f"'{folder}' holds no .mcap files to reindex")
    lines = []
    for path in files:
        if has_summary(path):
            lines.append(f"{path.name}: complete")
        else:
            kept = rewrite(path)
            lines.append(f"{path.name}: was unfinished; rewritten with {kept} messages")
    previous = {}
    if (folder / "metadata.yaml").is_file():
        try:
            previous = {
                e["topic_metadata"]["name"]: e["topic_metadata"]
                for e in metadata.read(folder).get("topics_with_message_count", [])
            }
        except BagError:
            previous = {}
    topics: dict[str, metadata.TopicInfo] = {}
    infos = []
    for path in files:
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
                    type_hash=old.get("type_description_hash") or _hash(message.type),
                )  # fmt: skip
            topic.count += 1
            info.count += 1
            info.start_ns = (
                message.log_time if info.count == 1 else min(info.start_ns, message.log_time)
            )
            info.end_ns = max(info.end_ns, message.log_time)
        infos.append(info)
    metadata.write(folder, list(topics.values()), infos)
    lines.append(
        f"metadata.yaml: {sum(t.count for t in topics.values())} messages on {len(topics)} topics"
    )
    return lines


def _hash(type_name: str) -> str:
    from rosl.idl import registry
    from rosl.idl.errors import InterfaceError

    try:
        registry.get_message_class(type_name)
        return registry.store().type_hash(type_name)
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
