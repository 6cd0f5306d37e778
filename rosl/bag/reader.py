"""Reading recordings: a rosbag2 folder, a folder of MCAP or ``.db3`` files, one such file.

A file without its summary (a recorder that was killed) is read record by record up to the
last complete one, and said so; ``rosl bag reindex`` rewrites it whole. ``.db3`` files
(rosbag2's sqlite3 storage) are read by :mod:`rosl.bag.sqlite`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, BinaryIO

from rosl.bag import metadata, sqlite
from rosl.bag.errors import BagError

if TYPE_CHECKING:
    from collections.abc import Iterable, Iterator
    from pathlib import Path

MAGIC = b"\x89MCAP0\r\n"
_SPLIT_INDEX = re.compile(r"^(?P<stem>.*?)(?:_(?P<index>\d+))?$")


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


def bag_files(target: Path) -> tuple[list[Path], dict[str, Any] | None]:
    """The MCAP or ``.db3`` files of a bag (folder or file) and its metadata, if any.

    Raises:
        BagError: missing target, no bag files, metadata naming missing files, a file that is
            not MCAP (not SQLite for ``.db3``), a compressed sqlite3 bag.
    """
    if not target.exists():
        raise BagError(f"no recording at '{target}'")
    if target.is_file():
        _check(target)
        return [target], None
    if (target / "metadata.yaml").is_file():
        info = metadata.read(target)
        sqlite.check_compression(target, info)
        files = [target / name for name in info["relative_file_paths"]]
        missing = [str(p.name) for p in files if not p.is_file()]
        if missing:
            raise BagError(
                f"{target / 'metadata.yaml'} names files that are not there: {', '.join(missing)} "
                f"(run `rosl bag reindex {target}` to rebuild it from the .mcap files present)"
            )
    else:
        info = None
        found = [*target.glob("*.mcap"), *target.glob(f"*{sqlite.SUFFIX}")]
        files = split_order(p for p in found if p.stat().st_size)  # an empty one holds nothing
        if not files:
            raise BagError(f"'{target}' holds no metadata.yaml and no .mcap or .db3 files")
    for path in files:
        _check(path)
    return files, info


def _check(path: Path) -> None:
    if sqlite.is_db3(path):
        sqlite.check(path)
    else:
        check_magic(path)


def split_order(paths: Iterable[Path]) -> list[Path]:
    """MCAP files in the order they were split: ``run_2`` before ``run_10``.

    Files are grouped by their name without the trailing ``_N`` and ordered by ``N`` as a
    number (a name without an index first).
    """

    def key(path: Path) -> tuple[str, int, str]:
        match = _SPLIT_INDEX.match(path.stem)
        assert match is not None  # every name matches: the index is optional
        index = match["index"]
        return (match["stem"], int(index) if index is not None else -1, path.name)

    return sorted(paths, key=key)


def check_magic(
    path: Path,
    magic: bytes = MAGIC,
    refusal: str = "is not an MCAP file (it does not start with the MCAP magic)",
) -> None:
    """Raise a one-line BagError (``path`` and ``refusal``) unless ``path`` starts with ``magic``.

    Raises:
        BagError: the file cannot be read or does not start so.
    """
    try:
        with path.open("rb") as handle:
            head = handle.read(len(magic))
    except OSError as err:
        raise BagError(f"cannot read {path}: {err.strerror}") from None
    if head != magic:
        raise BagError(f"{path} {refusal}")


def has_summary(path: Path) -> bool:
    """Whether an MCAP file ends with its footer (was finished properly); a ``.db3`` always is."""
    if sqlite.is_db3(path):
        return True  # SQLite commits whole transactions: there is no torn end to repair
    with path.open("rb") as handle:
        handle.seek(0, 2)
        size = handle.tell()
        if size < 2 * len(MAGIC):
            return False
        handle.seek(size - len(MAGIC))
        return handle.read(len(MAGIC)) == MAGIC


def iter_file(path: Path, topics: set[str] | None = None) -> Iterator[BagMessage]:
    """Messages of one MCAP or ``.db3`` file in log-time order (stream order if unfinished).

    Raises:
        BagError: a chunk that cannot be read (damaged, not decompressible) after the first
            messages: one line that names the file and the repair.
    """
    if sqlite.is_db3(path):
        yield from sqlite.iter_messages(path, topics)
        return
    with path.open("rb") as handle:
        if not has_summary(path):  # unfinished: up to its torn tail
            yield from iter_records(handle, topics)
            return
        yielded = 0
        try:
            for message in _iter_indexed(handle, topics):
                yielded += 1
                yield message
            return
        except Exception as err:  # the mcap library's, zstd's or lz4's: a damaged file
            if yielded:  # read again from the start, they would come twice
                raise BagError(damaged(path, err)) from None
        handle.seek(0)  # a summary that does not hold: read it record by record, to its end
        failures: list[Exception] = []
        yield from iter_records(handle, topics, failures)
        if failures:  # a finished file ends cleanly: this one is damaged
            raise BagError(damaged(path, failures[0]))


def damaged(path: Path, err: BaseException) -> str:
    """The one line for a file that cannot be read on: what failed, and the repair."""
    reason = (str(err).splitlines() or [type(err).__name__])[0][:120]
    return (
        f"cannot read {path}: {reason} (a damaged chunk? `rosl bag reindex {path.parent} "
        "--keep-corrupt` rewrites it with what can be read)"
    )


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


def stream_records(handle: BinaryIO, failures: list[Exception] | None = None) -> Iterator[Any]:
    """The records of an MCAP stream in file order (chunks opened), up to a torn tail.

    What ended the stream early (a torn tail, a damaged chunk) goes to ``failures``.
    """
    from mcap.stream_reader import StreamReader

    records = StreamReader(handle, skip_magic=False, emit_chunks=False).records
    while True:
        try:
            record = next(records)
        except StopIteration:
            return
        except Exception as err:  # whatever the library raises on what it cannot read
            if failures is not None:
                failures.append(err)
            return
        yield record


def iter_records(
    handle: BinaryIO, topics: set[str] | None = None, failures: list[Exception] | None = None
) -> Iterator[BagMessage]:
    """Messages of an MCAP stream read record by record, stopping at a torn tail.

    What ended the stream early goes to ``failures`` (see :func:`stream_records`).
    """
    from mcap.records import Channel as McapChannel
    from mcap.records import Message, Schema

    schemas: dict[int, Any] = {}
    channels: dict[int, Any] = {}
    for record in stream_records(handle, failures):
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
