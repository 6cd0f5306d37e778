"""rosbag2's sqlite3 storage: ``.db3`` files, read in every layout rosbag2 wrote, and written.

A ``.db3`` file is an SQLite database. ``topics`` names each topic (type and serialization
format; ``offered_qos_profiles`` since Foxy, a YAML text; ``type_description_hash`` since
Iron), ``messages`` holds each payload with its receive time in nanoseconds. Newer layouts add
``schema`` (the layout's number and the distro), ``metadata`` (the bag's metadata as YAML) and
``message_definitions`` (each type's ``ros2msg``/``ros2idl`` text). Files are opened read-only
and the tables and columns present decide what is read, so every layout reads alike. A type
without a stored definition is described by rosl's own interfaces when it knows the type.

Written files take the newest layout (schema version 4, as Iron and later write it; older
releases read the tables and columns they know). Each topic's QoS text follows the metadata
version of the distro the bag is labelled with, as that distro's reader parses it.
"""

from __future__ import annotations

import contextlib
import sqlite3
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from rosl.bag import metadata
from rosl.bag.errors import BagError

if TYPE_CHECKING:
    from collections.abc import Iterator, Mapping
    from pathlib import Path

    from rosl.bag.reader import BagMessage

SUFFIX = ".db3"
STORAGE = "sqlite3"
SCHEMA_VERSION = 4
MAGIC = b"SQLite format 3\x00"
_ENCODINGS = ("ros2msg", "ros2idl")
_MOST_PARAMETERS = 500  # topics filtered in SQL; more are filtered here (SQLite's limit is 999)
_LAYOUT = """
CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);
CREATE TABLE metadata(
  id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);
CREATE TABLE topics(
  id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
  serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL,
  type_description_hash TEXT NOT NULL);
CREATE TABLE message_definitions(
  id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL, encoding TEXT NOT NULL,
  encoded_message_definition TEXT NOT NULL, type_description_hash TEXT NOT NULL);
CREATE TABLE messages(
  id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL,
  data BLOB NOT NULL);
CREATE INDEX timestamp_idx ON messages (timestamp ASC);
"""


@dataclass(frozen=True, slots=True)
class Topic:
    """One row of a file's ``topics`` table, with its type's definition and message count."""

    id: int
    name: str
    type: str
    serialization_format: str = "cdr"
    offered_qos_profiles: str = ""  # YAML text (empty before Foxy)
    type_hash: str = ""  # RIHS01 (empty before Iron)
    schema_encoding: str = ""  # ros2msg or ros2idl; empty when nobody could describe the type
    schema_text: str = ""
    count: int = 0
    start_ns: int = 0  # the first and last timestamps of its messages
    end_ns: int = 0

    def channel_metadata(self) -> dict[str, str]:
        """The topic's MCAP channel metadata, as rosbag2's MCAP storage keeps it."""
        found = {"offered_qos_profiles": self.offered_qos_profiles,
                 "topic_type_hash": self.type_hash}  # fmt: skip
        return {key: value for key, value in found.items() if value}


@dataclass(frozen=True, slots=True)
class Summary:
    """What one ``.db3`` file holds, from SQL aggregates (no payload is read).

    Messages of a topic the ``topics`` table does not list are not counted: no reader sees them.
    """

    topics: list[Topic]
    start_ns: int
    end_ns: int
    count: int


def is_db3(path: Path) -> bool:
    """Whether ``path`` is named as rosbag2's sqlite3 storage names its files."""
    return path.suffix == SUFFIX


def check(path: Path) -> None:
    """Raise a one-line BagError unless ``path`` starts as an SQLite database does.

    Raises:
        BagError: the file cannot be read or is not SQLite.
    """
    from rosl.bag.reader import check_magic

    check_magic(path, MAGIC, "is not a rosbag2 sqlite3 file (not an SQLite database)")


def check_compression(folder: Path, info: Mapping[str, Any]) -> None:
    """Refuse a sqlite3 bag whose metadata says its files or messages are compressed.

    Raises:
        BagError: naming the metadata file and the compression.
    """
    mode = str(info.get("compression_mode") or "")
    if str(info.get("storage_identifier") or "") == STORAGE and mode:
        kind = str(info.get("compression_format") or "") or "unknown format"
        raise BagError(
            f"{folder / 'metadata.yaml'}: a sqlite3 bag with {mode} compression ({kind}); "
            f"rosl reads uncompressed .db3 files only (decompress it first)"
        )


def summary(path: Path) -> Summary:
    """Topics with their counts, and the first and last timestamps, of one ``.db3`` file.

    Raises:
        BagError: not SQLite, no ``topics`` or ``messages`` table, or unreadable.
    """
    with _open(path) as (db, tables):
        topics = _topics(db, tables, counts=True)
    held = [t for t in topics if t.count]
    start = min((t.start_ns for t in held), default=0)
    return Summary(topics, start, max((t.end_ns for t in held), default=0),
                   sum(t.count for t in held))  # fmt: skip


def iter_messages(path: Path, topics: set[str] | None = None) -> Iterator[BagMessage]:
    """Messages of one ``.db3`` file in timestamp order (rosbag2's: then by row).

    The receive time is the log and the publish time; the sequence is 0 (not stored).

    Raises:
        BagError: not SQLite, no ``topics`` or ``messages`` table, or unreadable.
    """
    from rosl.bag.reader import BagMessage

    with _open(path) as (db, tables):
        listed = {t.id: t for t in _topics(db, tables) if not topics or t.name in topics}
        if not listed:
            return
        query, args = "SELECT topic_id, timestamp, data FROM messages", list(listed)
        if topics and len(args) <= _MOST_PARAMETERS:
            query += f" WHERE topic_id IN ({', '.join('?' * len(args))})"
        else:
            args = []
        described = {key: (t, t.channel_metadata()) for key, t in listed.items()}
        for topic_id, timestamp, data in db.execute(f"{query} ORDER BY timestamp, id", args):
            found = described.get(topic_id)
            if found is None:
                continue  # another topic, or a message of no listed topic
            topic, channel = found
            yield BagMessage(
                topic.name, topic.type, timestamp, timestamp, 0, bytes(data),
                topic.schema_encoding, topic.schema_text, channel,
            )  # fmt: skip


@contextlib.contextmanager
def _open(path: Path) -> Iterator[tuple[sqlite3.Connection, set[str]]]:
    """A read-only connection and the file's table names; SQLite's errors as one line."""
    try:
        db = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True)
    except sqlite3.Error as err:
        raise BagError(f"cannot open {path}: {err}") from None
    try:
        tables = {row[0] for row in db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        for table in ("topics", "messages"):
            if table not in tables:
                raise BagError(f"{path} is not a rosbag2 sqlite3 file (it has no '{table}' table)")
        yield db, tables
    except sqlite3.Error as err:
        raise BagError(f"cannot read {path} as a rosbag2 sqlite3 file: {err}") from None
    finally:
        db.close()


def _topics(db: sqlite3.Connection, tables: set[str], *, counts: bool = False) -> list[Topic]:
    columns = {row[1] for row in db.execute("PRAGMA table_info(topics)")}
    optional = [name if name in columns else "''"
                for name in ("offered_qos_profiles", "type_description_hash")]  # fmt: skip
    rows = db.execute(
        f"SELECT id, name, type, serialization_format, {', '.join(optional)} "
        "FROM topics ORDER BY id"
    ).fetchall()
    spans = {
        key: (count, first, last)
        for key, count, first, last in db.execute(
            "SELECT topic_id, COUNT(*), MIN(timestamp), MAX(timestamp) FROM messages "
            "GROUP BY topic_id"
        )
    } if counts else {}  # fmt: skip
    stored = _definitions(db) if "message_definitions" in tables else {}
    schemas: dict[str, tuple[str, str]] = {}
    topics = []
    for key, name, type_name, serialization, qos, digest in rows:
        if type_name not in schemas:
            schemas[type_name] = stored.get(type_name) or _known(str(type_name))
        encoding, text = schemas[type_name]
        count, first, last = spans.get(key, (0, 0, 0))
        topics.append(
            Topic(int(key), str(name), str(type_name), str(serialization or "cdr"),
                  str(qos or ""), str(digest or ""), encoding, text, count, first, last)
        )  # fmt: skip
    return topics


def _definitions(db: sqlite3.Connection) -> dict[str, tuple[str, str]]:
    """Each type's (encoding, text) the file stores (the first of a type; none unknown)."""
    found: dict[str, tuple[str, str]] = {}
    for type_name, encoding, text in db.execute(
        "SELECT topic_type, encoding, encoded_message_definition FROM message_definitions "
        "ORDER BY id"
    ):
        if encoding in _ENCODINGS and text and type_name not in found:
            found[str(type_name)] = (str(encoding), str(text))
    return found


def _known(type_name: str) -> tuple[str, str]:
    """(encoding, text) of a type rosl's interfaces describe, else empty."""
    from rosl.idl import registry
    from rosl.idl.errors import InterfaceError

    try:
        return registry.schema(type_name)
    except InterfaceError:
        return "", ""


class Db3File:
    """One ``.db3`` file being written: topics and messages in one transaction, then finish."""

    def __init__(self, path: Path, ros_distro: str = metadata.DISTRO) -> None:
        """Create ``path`` with rosbag2's tables, labelled with ``ros_distro``.

        It offers :class:`rosl.bag.writer.BagFile`'s calls (``channel``, ``write``,
        ``finish``, ``abandon``), so ``filter`` and ``convert`` write either storage alike.

        Raises:
            BagError: the file exists or cannot be created.
        """
        if path.exists():
            raise BagError(f"cannot write {path}: it exists already")
        self.path = path
        self.info = metadata.FileInfo(path.name)
        self.version = metadata.VERSIONS[ros_distro]
        self._topics: dict[str, int] = {}
        self._types: set[str] = set()
        try:
            self._db = sqlite3.connect(path)
        except sqlite3.Error as err:
            raise BagError(f"cannot write {path}: {err}") from None
        with self._writing():
            self._db.executescript(_LAYOUT)
            self._db.execute(
                "INSERT INTO schema (schema_version, ros_distro) VALUES (?, ?)",
                (SCHEMA_VERSION, ros_distro),
            )

    def _add_topic(
        self,
        topic: metadata.TopicInfo,
        qos_text: str = "",
        schema: tuple[str, str] = ("", ""),
    ) -> int:
        """Add a topic (its type's definition the first time the type is seen); its row id.

        Args:
            topic: name, type, serialization format and type hash.
            qos_text: the ``offered_qos_profiles`` YAML text.
            schema: (encoding, text) of the type; a definition of another encoding is left out.
        """
        with self._writing():
            cursor = self._db.execute(
                "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles, "
                "type_description_hash) VALUES (?, ?, ?, ?, ?)",
                (topic.name, topic.type, topic.serialization_format, qos_text, topic.type_hash),
            )
            if topic.type not in self._types and schema[0] in _ENCODINGS:
                self._db.execute(
                    "INSERT INTO message_definitions (topic_type, encoding, "
                    "encoded_message_definition, type_description_hash) VALUES (?, ?, ?, ?)",
                    (topic.type, schema[0], schema[1], topic.type_hash),
                )
        self._types.add(topic.type)
        assert cursor.lastrowid is not None  # an INSERT always gives one
        self._topics[topic.name] = cursor.lastrowid
        return cursor.lastrowid

    def channel(self, topic: metadata.TopicInfo, encoding: str, text: str | bytes) -> int:
        """The row id of a topic, added with its QoS text and its type's definition."""
        found = self._topics.get(topic.name)
        if found is not None:
            return found
        qos = metadata.qos_text(topic.qos, self.version)
        return self._add_topic(topic, qos, _schema_of(topic.type, encoding, text))

    def write(
        self, channel_id: int, log_time: int, publish_time: int, sequence: int, data: bytes
    ) -> None:
        """Add one message (rosbag2's sqlite3 storage keeps only its receive time)."""
        del publish_time, sequence
        with self._writing():
            self._db.execute(
                "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)",
                (channel_id, log_time, data),
            )
        self.info.add(log_time)

    def finish(self, information: Mapping[str, Any], ros_distro: str = "") -> None:
        """Store the bag's metadata (as rosbag2 does on closing), commit and close."""
        del ros_distro  # the schema table holds it since the file was made
        with self._writing():
            self._db.execute(
                "INSERT INTO metadata (metadata_version, metadata) VALUES (?, ?)",
                (self.version, metadata.serialized(information)),
            )
            self._db.commit()
        self._db.close()

    def abandon(self) -> None:
        """Close without committing and remove the file."""
        with contextlib.suppress(sqlite3.Error):
            self._db.close()
        with contextlib.suppress(OSError):
            self.path.unlink(missing_ok=True)

    @contextlib.contextmanager
    def _writing(self) -> Iterator[None]:
        try:
            yield
        except sqlite3.Error as err:
            self.abandon()
            raise BagError(f"cannot write {self.path}: {err}") from None


def _schema_of(type_name: str, encoding: str, text: str | bytes) -> tuple[str, str]:
    """(encoding, text) of a type: the one given when it is a definition, else rosl's."""
    if encoding in _ENCODINGS and text:
        return encoding, text.decode(errors="replace") if isinstance(text, bytes) else text
    return _known(type_name)
