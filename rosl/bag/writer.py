"""One MCAP file of a rosbag2 bag, written as rosbag2's MCAP storage plugin writes it.

The one writer behind ``record``, ``reindex``, ``filter`` and ``convert``:

- the ``ros2`` profile, chunks of ``CHUNK_SIZE`` (zstd, lz4 or none), with the index and
  summary that make the file seekable;
- a schema per type, named ``pkg/msg/Name`` with its ``ros2msg`` text (``MSG: pkg/Name``
  sections). A type nobody could describe still gets a schema record, of encoding
  ``unknown`` and no text, as rosbag2 writes it: its readers need a schema for every channel;
- a channel per topic, ``cdr``, whose metadata holds ``offered_qos_profiles`` (a YAML text in
  the bag's layout) and ``topic_type_hash`` (RIHS01). A topic is given its channel when it is
  recorded, before its first message, so a topic that never had a message is in the file too;
- at the end a metadata record named ``rosbag2`` holding ``serialized_metadata`` (the bag's
  ``rosbag2_bagfile_information`` as YAML) and ``ROS_DISTRO``, as Humble's and Jazzy's
  plugins leave them for their readers.

Writes the disk refuses raise a one-line :class:`BagError` naming the file.
"""

from __future__ import annotations

import contextlib
import os
from typing import TYPE_CHECKING, Any

from rosl.bag import metadata
from rosl.bag.errors import BagError

if TYPE_CHECKING:
    from collections.abc import Iterator, Mapping
    from pathlib import Path

CHUNK_SIZE = 4 * 1024 * 1024
COMPRESSIONS = ("zstd", "lz4", "none")
MESSAGE_RECORD = 31  # bytes of an MCAP message record besides its data
UNKNOWN_SCHEMA = "unknown"  # rosbag2's schema encoding for a type it found no definition of


class BagFile:
    """One MCAP file being written: channels, messages, then :meth:`finish`."""

    def __init__(
        self,
        path: Path,
        *,
        compression: str | None = None,
        library: str = "rosl",
        version: int = metadata.VERSIONS[metadata.DISTRO],
        chunk_size: int = CHUNK_SIZE,
    ) -> None:
        """Create ``path`` and write the MCAP header.

        Args:
            path: the file to create (replaced if it exists).
            compression: ``zstd``, ``lz4``, or ``none``/None.
            library: the writer's name in the header.
            version: the metadata version whose QoS layout the channels carry.
            chunk_size: bytes of messages per chunk.

        Raises:
            BagError: the file cannot be created, or an unknown compression.
        """
        from mcap.writer import CompressionType, Writer

        kinds = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4,
                 "none": CompressionType.NONE, None: CompressionType.NONE}  # fmt: skip
        if compression not in kinds:
            raise BagError(f"unknown compression '{compression}' (zstd, lz4 or none)")
        self.path = path
        self.compression = "" if compression in (None, "none") else str(compression)
        self.version = version
        self.info = metadata.FileInfo(path.name)
        self.unchunked = 0  # message bytes in the chunk being built (counted uncompressed)
        self._position = 0  # where the handle was when the last chunk went out
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._finished = False
        try:
            self._handle = path.open("wb")
        except OSError as err:
            raise BagError(f"cannot create {path}: {err.strerror}") from None
        self._writer = Writer(self._handle, chunk_size=chunk_size, compression=kinds[compression])
        with self._failing("write"):
            self._writer.start(profile="ros2", library=library)
            self._handle.flush()  # on disk at once: a file killed now is still MCAP
            os.fsync(self._handle.fileno())

    # --- channels and messages ---------------------------------------------------------------

    def channel(self, topic: metadata.TopicInfo, encoding: str, text: str | bytes) -> int:
        """The channel id of a topic, registered (with its type's schema) the first time."""
        found = self._channels.get(topic.name)
        if found is not None:
            return found
        schema_id = self._schemas.get(topic.type)
        with self._failing("write"):
            if schema_id is None:
                data = text.encode() if isinstance(text, str) else bytes(text)
                schema_id = self._writer.register_schema(
                    topic.type, encoding if encoding and data else UNKNOWN_SCHEMA, data
                )
                self._schemas[topic.type] = schema_id
            channel_id: int = self._writer.register_channel(
                topic.name,
                topic.serialization_format or "cdr",
                schema_id,
                {
                    "offered_qos_profiles": metadata.qos_text(topic.qos, self.version),
                    "topic_type_hash": topic.type_hash,
                },
            )
        self._channels[topic.name] = channel_id
        return channel_id

    def has_channel(self, name: str) -> bool:
        """Whether a topic has its channel in this file."""
        return name in self._channels

    def write(
        self, channel_id: int, log_time: int, publish_time: int, sequence: int, data: bytes
    ) -> None:
        """Add one message (its bytes as they are)."""
        with self._failing("write"):
            self._writer.add_message(
                channel_id=channel_id, log_time=log_time, data=data,
                publish_time=publish_time, sequence=sequence,
            )  # fmt: skip
        self.info.add(log_time)
        self.unchunked += MESSAGE_RECORD + len(data)

    def size(self) -> int:
        """The file's size so far, the chunk being built counted uncompressed."""
        position = self._handle.tell()
        if position != self._position:  # a chunk went out since: it holds what was counted
            self._position = position
            self.unchunked = 0
        return position + self.unchunked

    # --- the file ----------------------------------------------------------------------------

    def flush(self, sync: bool = True) -> None:
        """Close the chunk being built and write it out (and fsync, unless ``sync`` is false)."""
        with self._failing("write"):
            self._writer.flush()
            if sync:
                self._handle.flush()
                os.fsync(self._handle.fileno())
        self._position = self._handle.tell()
        self.unchunked = 0

    def finish(self, information: Mapping[str, Any] | None = None, ros_distro: str = "") -> None:
        """Write the ``rosbag2`` metadata record, the index and summary; fsync and close.

        Args:
            information: the bag's ``rosbag2_bagfile_information`` as it stands (None: no
                ``serialized_metadata``).
            ros_distro: the distro the bag is labelled with.
        """
        if self._finished:
            return
        record: dict[str, str] = {}
        if information is not None:
            record["serialized_metadata"] = metadata.serialized(information)
        if ros_distro:
            record["ROS_DISTRO"] = ros_distro
        with self._failing("finish"):
            if record:
                self._writer.add_metadata("rosbag2", record)
            self._writer.finish()
            self._handle.flush()
            os.fsync(self._handle.fileno())
            self._handle.close()
        self._finished = True

    def abandon(self) -> None:
        """Close the file as it is, unfinished (after a failed write: reindex repairs it)."""
        self._finished = True
        with contextlib.suppress(OSError):
            self._handle.close()

    @contextlib.contextmanager
    def _failing(self, verb: str) -> Iterator[None]:
        try:
            yield
        except OSError as err:
            reason = err.strerror or type(err).__name__
            raise BagError(f"cannot {verb} {self.path}: {reason} (disk full?)") from None
