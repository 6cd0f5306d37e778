"""What an MCAP file still holds, read record by record, trusting nothing it has not checked.

The mcap library reads a chunk whole or not at all, and takes a chunk whose CRC fails as it
is. Here records are read by hand (opcode u8, length u64, body): a file cut short gives every
record that is complete before the cut, also those inside a chunk cut short (what its
compressed prefix decompresses to, cut to whole records). A complete chunk is checked against
its ``uncompressed_crc`` (0: not computed); one that fails it, or cannot be decompressed, is
noted in :attr:`Scan.bad` (with the count of messages its message index records give) and
its messages are left out unless they are asked for; its Schema and Channel records are kept,
as later chunks' messages need them. Records outside chunks (unchunked files) are read too.
Yields the Schema, Channel and Message records of the ``mcap`` library, in file order.
"""

from __future__ import annotations

import io
import os
import struct
import zlib
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, BinaryIO

from mcap.data_stream import ReadDataStream
from mcap.records import Channel, Message, Schema

if TYPE_CHECKING:
    from collections.abc import Iterator

MAGIC = b"\x89MCAP0\r\n"
FOOTER, SCHEMA, CHANNEL, MESSAGE, CHUNK, MESSAGE_INDEX, METADATA = 2, 3, 4, 5, 6, 7, 12
_RECORD = struct.Struct("<BQ")  # opcode, body length
_CHUNK = struct.Struct("<QQQII")  # start, end, uncompressed size and CRC, len(compression)
_LENGTH = struct.Struct("<Q")
_MESSAGE = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time; then the data
_INDEX_HEAD, _INDEX_ENTRY = 6, 16  # a message index: channel id u16, entries (u32 length + 16 each)
_PIECE = 1 << 16  # compressed bytes fed at a time: what came before a broken piece is kept

Record = Schema | Channel | Message


@dataclass(slots=True)
class BadChunk:
    """A complete chunk whose records cannot be trusted."""

    offset: int  # of its record in the file
    reason: str  # "fails its CRC check", ...
    readable: int  # message records that could be read from it
    indexed: int = 0  # messages its message index records list

    @property
    def messages(self) -> int:
        """How many messages the chunk holds, as well as it can be told."""
        return self.indexed or self.readable


@dataclass(slots=True)
class Scan:
    """What one pass over a file found (filled in while its records are read)."""

    finished: bool = False  # read up to its footer and closing magic
    end: int = 0  # where the readable part ends
    cut_messages: int = 0  # messages taken from a chunk cut short
    unreadable: int = 0  # complete records outside chunks that do not parse
    bad: list[BadChunk] = field(default_factory=list)
    distro: str = ""  # ROS_DISTRO of the file's rosbag2 metadata record


def first_compression(handle: BinaryIO) -> str:
    """The compression of the file's first chunk ("" for none, or when it has no chunk)."""
    handle.seek(len(MAGIC))
    while len(head := handle.read(_RECORD.size)) == _RECORD.size:
        opcode, length = _RECORD.unpack(head)
        if opcode == CHUNK:
            body = handle.read(_CHUNK.size)
            if len(body) < _CHUNK.size:
                return ""
            return handle.read(_CHUNK.unpack(body)[4]).decode(errors="replace")
        handle.seek(length, io.SEEK_CUR)
    return ""


def records(handle: BinaryIO, scan: Scan, keep_bad: bool = False) -> Iterator[Record]:
    """The complete Schema, Channel and Message records of an MCAP file, in file order.

    Args:
        handle: the file, opened for reading (it starts with the MCAP magic).
        scan: filled in with what was found on the way.
        keep_bad: also yield what can be read from chunks that fail their check.

    Raises:
        OSError: the file cannot be read.
    """
    size = os.fstat(handle.fileno()).st_size
    handle.seek(len(MAGIC))
    position = chunk_offset = len(MAGIC)
    while len(head := handle.read(_RECORD.size)) == _RECORD.size:
        opcode, length = _RECORD.unpack(head)
        body = handle.read(min(length, size - position - _RECORD.size))
        whole = len(body) == length
        if opcode == CHUNK:
            chunk_offset = position  # the message index records that follow are its
            yield from _chunk(body, position, whole, scan, keep_bad)
        elif not whole:
            break
        elif opcode == FOOTER:
            scan.finished = handle.read(len(MAGIC)) == MAGIC
        elif opcode == METADATA:
            _metadata(body, scan)
        elif opcode == MESSAGE_INDEX and scan.bad and scan.bad[-1].offset == chunk_offset:
            scan.bad[-1].indexed += max(0, len(body) - _INDEX_HEAD) // _INDEX_ENTRY
        elif opcode in (SCHEMA, CHANNEL, MESSAGE):
            record = _parse(opcode, body)
            if record is None:
                scan.unreadable += 1
            else:
                yield record
        if not whole:
            break
        position += _RECORD.size + length
        if scan.finished:
            break
    scan.end = position


def _chunk(body: bytes, offset: int, whole: bool, scan: Scan, keep_bad: bool) -> Iterator[Record]:
    """The records of one chunk record (``whole``: not cut short)."""
    if len(body) < _CHUNK.size:
        return
    _, _, size, crc, name_length = _CHUNK.unpack_from(body)
    start = _CHUNK.size + name_length + _LENGTH.size
    if len(body) < start:
        return
    compression = body[_CHUNK.size : start - _LENGTH.size].decode(errors="replace")
    (length,) = _LENGTH.unpack_from(body, start - _LENGTH.size)
    data = body[start : start + length]
    complete = whole and len(data) == length
    plain, reason = _decompress(compression, data)
    if reason or not complete:
        pass  # cut short: nothing to check it against
    elif len(plain) != size:
        reason = "does not decompress to its stated size"
    elif crc and zlib.crc32(plain) != crc:
        reason = "fails its CRC check"
    found, parsed = _inner(plain)
    messages = sum(isinstance(r, Message) for r in found)
    if complete and reason:
        scan.bad.append(BadChunk(offset, reason, messages))
        if not keep_bad:
            found = [r for r in found if not isinstance(r, Message)]
    elif not parsed:
        scan.unreadable += 1
    if not complete:
        scan.cut_messages += messages
    yield from found


def _decompress(compression: str, data: bytes) -> tuple[bytes, str]:
    """What ``data`` decompresses to (a prefix when it is cut short or broken), and why not all.

    Returns:
        The bytes, and "" or the reason the rest could not be decompressed.
    """
    decompressor: Any
    if compression == "":
        return data, ""
    if compression == "zstd":
        import zstandard

        decompressor = zstandard.ZstdDecompressor().decompressobj()
    elif compression == "lz4":
        import lz4.frame

        decompressor = lz4.frame.LZ4FrameDecompressor()
    else:
        return b"", f"has an unknown compression '{compression}'"
    pieces = []
    try:
        for at in range(0, len(data), _PIECE):
            pieces.append(decompressor.decompress(data[at : at + _PIECE]))
    except Exception:  # each library has its own errors for broken input
        return b"".join(pieces), "cannot be decompressed"
    return b"".join(pieces), ""


def _inner(data: bytes) -> tuple[list[Record], bool]:
    """The complete records of a chunk's (decompressed, maybe cut) records; whether all parsed.

    Reading stops at the first complete record that does not parse: nothing after it is sure.
    """
    found: list[Record] = []
    position = 0
    while position + _RECORD.size <= len(data):
        opcode, length = _RECORD.unpack_from(data, position)
        end = position + _RECORD.size + length
        if end > len(data):
            break
        if opcode in (SCHEMA, CHANNEL, MESSAGE):
            record = _parse(opcode, data[position + _RECORD.size : end])
            if record is None:
                return found, False
            found.append(record)
        position = end
    return found, True


def _parse(opcode: int, body: bytes) -> Record | None:
    """One Schema, Channel or Message record from its body (None: it does not parse)."""
    if opcode == MESSAGE:  # the many: read directly
        if len(body) < _MESSAGE.size:
            return None
        channel_id, sequence, log_time, publish_time = _MESSAGE.unpack_from(body)
        return Message(channel_id, log_time, body[_MESSAGE.size :], publish_time, sequence)
    stream = ReadDataStream(io.BytesIO(body))
    try:
        record: Record = Schema.read(stream) if opcode == SCHEMA else Channel.read(stream)
    except Exception:  # a short or garbled body: EndOfFile, UnicodeError, ...
        return None
    return record


def _metadata(body: bytes, scan: Scan) -> None:
    """Note the distro a ``rosbag2`` metadata record names."""
    from mcap.records import Metadata

    try:
        record = Metadata.read(ReadDataStream(io.BytesIO(body)))
    except Exception:  # a garbled record names nothing
        return
    if record.name == "rosbag2" and record.metadata.get("ROS_DISTRO"):
        scan.distro = record.metadata["ROS_DISTRO"]
