"""``rosl bag reindex``: make a folder whole again after a crash, losing nothing it holds.

Every ``*.mcap`` file is checked to be MCAP before anything is touched, then read record by
record (:mod:`rosl.bag.salvage`). A finished file whose chunks all pass their CRC check is left
as it is. An unfinished one (its recorder was killed, or a copy was cut off) is rewritten with
every record that is complete before the cut, also those of a chunk cut short; a chunk whose
CRC fails is reported and its messages left out (``keep_corrupt`` keeps them). The rewrite
goes through the shared :class:`~rosl.bag.writer.BagFile` (the file's chunk compression, each
channel's QoS and type hash, the bag's distro label kept) into a temporary file that replaces
the original only once it is complete and on disk; when something could not be carried over,
the original stays beside it as ``<name>.mcap.orig``. A file with no complete message is left
as it was. Then ``metadata.yaml`` is rebuilt from the files in split order (``_2`` before
``_10``); topics the old one listed that no file holds stay, with count 0. A folder that is
already whole is said to be so, and nothing is written.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import shutil
from typing import TYPE_CHECKING, Any

from mcap.records import Message, Schema

from rosl.bag import metadata, salvage
from rosl.bag.errors import BagError
from rosl.bag.reader import bag_files, check_magic, has_summary, split_order
from rosl.bag.writer import BagFile

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from mcap.records import Channel

_KEPT = " kept (--keep-corrupt)"
Previous = dict[str, dict[str, Any]]  # topic name -> its topic_metadata in the old metadata.yaml


class _Tally:
    """One file's topics and counts, taken from its records (written to ``bag`` as they come)."""

    def __init__(self, name: str, previous: Previous, bag: BagFile | None = None) -> None:
        self.info = metadata.FileInfo(name)
        self.topics: dict[str, metadata.TopicInfo] = {}
        self.skipped = 0  # messages of an unknown channel, or of another type than its topic's
        self._previous = previous
        self._bag = bag
        self._schemas: dict[int, Schema] = {}
        self._channels: dict[int, tuple[metadata.TopicInfo, int] | None] = {}

    def take(self, record: salvage.Record) -> None:
        """Count (and write) one record."""
        if isinstance(record, Message):
            found = self._channels.get(record.channel_id)
            if found is None:
                self.skipped += 1
                return
            topic, channel_id = found
            if self._bag is not None:
                self._bag.write(
                    channel_id, record.log_time, record.publish_time, record.sequence, record.data
                )
            topic.count += 1
            self.info.add(record.log_time)
        elif isinstance(record, Schema):
            self._schemas.setdefault(record.id, record)
        elif record.id not in self._channels:
            self._channels[record.id] = self._channel(record)

    def _channel(self, channel: Channel) -> tuple[metadata.TopicInfo, int] | None:
        schema = self._schemas.get(channel.schema_id)
        old = self._previous.get(channel.topic, {})
        type_name = schema.name if schema else str(old.get("type") or "")
        topic = self.topics.get(channel.topic)
        if topic is None:
            topic = self.topics[channel.topic] = metadata.TopicInfo(
                channel.topic, type_name, channel.message_encoding or "cdr",
                qos=metadata.offered_qos(channel.metadata)
                or metadata.parse_profiles(old.get("offered_qos_profiles")),
                type_hash=channel.metadata.get("topic_type_hash")
                or str(old.get("type_description_hash") or "") or _hash(schema),
            )  # fmt: skip
        elif topic.type != type_name:
            return None  # a second type on one topic: a rosbag2 file has one channel per topic
        if self._bag is None:
            return topic, 0
        text = schema.data if schema else b""
        return topic, self._bag.channel(topic, schema.encoding if schema else "", text)


def reindex(folder: Path, keep_corrupt: bool = False) -> list[str]:
    """Repair a recording folder; return a line per file (and chunk left out) and one more.

    Args:
        folder: the recording folder.
        keep_corrupt: keep the messages of chunks that fail their CRC check.

    Raises:
        BagError: not a folder, no .mcap files in it, a file that is not MCAP (nothing is
            changed then), or a file that cannot be read or rewritten (left as it was).
    """
    if not folder.is_dir():
        raise BagError(f"'{folder}' is not a recording folder")
    files = split_order(folder.glob("*.mcap"))
    stored = sorted(p.name for p in folder.glob("*.db3"))
    if stored:  # SQLite commits whole transactions: a .db3 is never left torn
        raise BagError(
            f"'{folder}' holds rosbag2 sqlite3 files ({', '.join(stored)}): they need no "
            "reindex; reindex repairs folders of .mcap files"
        )
    if not files:
        raise BagError(f"'{folder}' holds no .mcap files to reindex")
    empty = [p for p in files if p.stat().st_size == 0]  # killed before it wrote a byte
    files = [p for p in files if p not in empty]
    if not files:
        raise BagError(f"'{folder}' holds only empty .mcap files: nothing to reindex")
    for path in files:  # before anything is rewritten
        check_magic(path)
    old = _old_information(folder)
    custom = _custom(old)
    previous: Previous = {
        e["topic_metadata"]["name"]: e["topic_metadata"]
        for e in (old or {}).get("topics_with_message_count") or []
    }
    lines: dict[Path, list[str]] = {}
    tallies: dict[Path, _Tally] = {}
    distros = [os.environ.get("ROS_DISTRO", "")]  # the last resort: a killed recorder's label
    for path in filter(has_summary, files):  # finished files: are all their chunks sound?
        scan = salvage.Scan()
        tally = _Tally(path.name, previous)
        for record in _records(path, scan):
            tally.take(record)
        distros.insert(-1, scan.distro)
        if scan.finished and not (scan.bad or scan.unreadable or tally.skipped):
            tallies[path], lines[path] = tally, [f"{path.name}: complete"]
    label = metadata.labelled(old) if old else metadata.labelled({"ros_distro": _first(distros)})
    for path in files:
        if path not in lines:
            found, lines[path] = _rewrite(path, previous, label, keep_corrupt, custom)
            if found is not None:
                tallies[path] = found
    said = [f"{p.name}: empty (its recorder stopped before writing); left out" for p in empty]
    said += [line for path in files for line in lines[path]]
    if len(tallies) == len(files) and _matches(old, files, list(tallies.values())):
        return [*said, "metadata.yaml: matches the files; nothing was changed"]
    topics = _topics([tallies[p] for p in files if p in tallies], previous)
    infos = [tallies[p].info for p in files if p in tallies]
    listed = set((old or {}).get("relative_file_paths") or [])
    if listed - {info.path for info in infos}:  # a file it named is left out: keep it to read
        _replace_aside(folder / "metadata.yaml")
        said.append("metadata.yaml: the old one names files left out; kept as metadata.yaml.orig")
    metadata.write(folder, topics, infos, custom, ros_distro=label)
    total = sum(t.count for t in topics)
    return [*said, f"metadata.yaml: {total} messages on {len(topics)} topics"]


def _custom(old: dict[str, Any] | None) -> dict[str, str]:
    """The old metadata's ``custom_data`` (kept, as filter and convert keep it)."""
    custom = (old or {}).get("custom_data") or {}
    return {str(k): str(v) for k, v in custom.items()} if isinstance(custom, dict) else {}


def _replace_aside(path: Path) -> None:
    """Copy ``path`` to ``<path>.orig`` (on disk before anything replaces it)."""
    aside = path.with_name(path.name + ".orig")
    try:
        shutil.copyfile(path, aside)
        with aside.open("rb") as handle:
            os.fsync(handle.fileno())
    except OSError as err:
        raise BagError(f"cannot keep {path} as {aside.name}: {err.strerror}") from None


def _first(names: list[str]) -> str:
    return next((name for name in names if name), "")


def _records(path: Path, scan: salvage.Scan, keep_bad: bool = False) -> Iterator[salvage.Record]:
    """The records of one file (see :func:`salvage.records`).

    Raises:
        BagError: the file cannot be read.
    """
    try:
        with path.open("rb") as handle:
            yield from salvage.records(handle, scan, keep_bad)
    except OSError as err:
        raise BagError(f"cannot read {path}: {err.strerror or type(err).__name__}") from None


def _rewrite(
    path: Path, previous: Previous, label: str, keep_corrupt: bool, custom: dict[str, str]
) -> tuple[_Tally | None, list[str]]:
    """Rewrite one file whole; its tally (None: left as it was) and the lines that say so.

    Raises:
        BagError: the new file cannot be written; the original is left untouched.
    """
    temporary = path.with_name(path.name + ".reindex")
    scan = salvage.Scan()
    try:
        with path.open("rb") as handle:
            compression = salvage.first_compression(handle)
        bag = BagFile(
            temporary, compression=compression if compression in ("zstd", "lz4") else "none",
            library="rosl reindex", version=metadata.VERSIONS[label],
        )  # fmt: skip
        try:
            tally = _Tally(path.name, previous, bag)
            for record in _records(path, scan, keep_corrupt):
                tally.take(record)
            if tally.info.count:
                topics = list(tally.topics.values())
                information = metadata.information(
                    topics, [tally.info], custom=custom, ros_distro=label
                )
                bag.finish(information, label)
        finally:
            bag.abandon()  # closed as it is, unless finished
    except BaseException as err:
        _remove(temporary)
        if not isinstance(err, Exception):
            raise  # Ctrl-C: the original is untouched, the partial copy gone
        if isinstance(err, BagError):
            reason = str(err)
        elif isinstance(err, OSError):
            reason = f"cannot read {path}: {err.strerror}"
        else:  # the file holds something no reader foresaw
            reason = f"cannot rewrite {path}: {type(err).__name__}: {err}"
        raise BagError(f"{reason} ({path.name} was left as it was)") from None
    lost = _lost(path, scan, tally, keep_corrupt)
    lines = [f"{path.name}: {text}" for text in lost]
    if not tally.info.count:
        _remove(temporary)
        lines.append(
            f"{path.name}: holds no complete message it can vouch for; left as it was "
            "(not listed in metadata.yaml)"
        )
        return None, lines
    said = "was unfinished; rewritten" if not has_summary(path) else "rewritten"
    said += f" with {tally.info.count} messages"
    if scan.cut_messages:
        said += f" ({scan.cut_messages} of them from a chunk cut short)"
    aside = _replace(path, temporary, keep=any(not text.endswith(_KEPT) for text in lost))
    if aside is not None:
        said += f"; the original is kept as {aside.name}"
    return tally, [*lines, f"{path.name}: {said}"]


def _lost(path: Path, scan: salvage.Scan, tally: _Tally, keep_corrupt: bool) -> list[str]:
    """What of a file could not be carried over (or only with ``keep_corrupt``), a phrase each."""
    lost = []
    for bad in scan.bad:
        said = f"the chunk at byte {bad.offset} {bad.reason}; "
        if not keep_corrupt:
            said += f"its {bad.messages} messages were left out"
        elif bad.readable < bad.messages:
            said += f"{bad.readable} of its {bad.messages} messages could be read and were kept"
        else:
            said += f"its {bad.messages} messages were{_KEPT}"
        lost.append(said)
    if has_summary(path) and not scan.finished:
        lost.append(f"unreadable from byte {scan.end} on")
    if scan.unreadable:
        lost.append(f"{scan.unreadable} records that do not parse were left out")
    if tally.skipped:
        lost.append(
            f"{tally.skipped} messages of a channel it does not define (or of a second type on "
            "a topic) were left out"
        )
    return lost


def _replace(path: Path, temporary: Path, keep: bool) -> Path | None:
    """Put the finished ``temporary`` in place of ``path``; the original's new name if kept.

    Raises:
        BagError: the disk refused; ``path`` is as it was.
    """
    aside = None
    try:
        if keep:
            aside = next(
                candidate
                for candidate in (path.with_name(f"{path.name}.orig{n or ''}") for n in range(1000))
                if not candidate.exists()
            )
            try:
                os.link(path, aside)  # the original stays where it is until it is replaced
            except OSError:
                shutil.copy2(path, aside)  # a file system without hard links
                with aside.open("rb") as handle:
                    os.fsync(handle.fileno())  # the copy on disk before the original goes
        temporary.replace(path)
    except OSError as err:
        _remove(temporary)
        raise BagError(
            f"cannot replace {path}: {err.strerror or type(err).__name__} (it was left as it was)"
        ) from None
    metadata.sync_folder(path.parent)  # the renames on disk too
    return aside


def _remove(temporary: Path) -> None:
    """Remove a partial rewrite (never a folder someone put in its place)."""
    with contextlib.suppress(OSError):
        if temporary.is_file():
            temporary.unlink()


def _old_information(folder: Path) -> dict[str, Any] | None:
    """An existing, readable ``metadata.yaml``."""
    if not (folder / "metadata.yaml").is_file():
        return None
    try:
        return metadata.read(folder)
    except BagError:
        return None


def _matches(old: dict[str, Any] | None, files: list[Path], tallies: list[_Tally]) -> bool:
    """Whether the old metadata.yaml lists these files and counts what they hold."""
    if old is None or list(old.get("relative_file_paths") or []) != [p.name for p in files]:
        return False
    listed = {
        e["topic_metadata"]["name"]: e.get("message_count")
        for e in old.get("topics_with_message_count") or []
    }
    counted = {topic.name: topic.count for topic in _topics(tallies, {})}
    per_file = [(e.get("path"), e.get("message_count")) for e in old.get("files") or []]
    return (
        {name: n for name, n in listed.items() if n}
        == {name: n for name, n in counted.items() if n}
        and old.get("message_count") == sum(counted.values())
        and per_file in ([], [(t.info.path, t.info.count) for t in tallies])
    )


def _topics(tallies: list[_Tally], previous: Previous) -> list[metadata.TopicInfo]:
    """The topics of all files (counts added up), then those only the old metadata listed."""
    topics: dict[str, metadata.TopicInfo] = {}
    for tally in tallies:
        for topic in tally.topics.values():
            if topic.name in topics:
                topics[topic.name].count += topic.count
            else:
                topics[topic.name] = dataclasses.replace(topic)
    for name, old in previous.items():  # listed before, but in no file: count 0
        if name not in topics:
            topics[name] = metadata.TopicInfo(
                name, str(old.get("type") or ""), str(old.get("serialization_format") or "cdr"),
                qos=metadata.parse_profiles(old.get("offered_qos_profiles")),
                type_hash=str(old.get("type_description_hash") or ""),
            )  # fmt: skip
    return list(topics.values())


def _hash(schema: Schema | None) -> str:
    """The RIHS01 hash of a schema's type: from its text, else this process's type."""
    from rosl.idl import registry
    from rosl.idl.errors import InterfaceError

    if schema is None:
        return ""
    if schema.encoding and schema.data:
        with contextlib.suppress(InterfaceError, UnicodeDecodeError):
            return registry.store().schema_type_hash(
                schema.name, schema.encoding, schema.data.decode()
            )
    try:
        registry.get_message_class(schema.name)
        return registry.store().type_hash(schema.name)
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
