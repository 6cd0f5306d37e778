"""The fixed header every rosl datagram starts with (48 bytes, little endian).

A datagram is this header, the payload, and — when the sender has a key (see ``auth.py``)
and sets :attr:`Flags.SIGNED` — a 16-byte MAC over both. ``sender`` is drawn at random when a
process starts: it is the session id that makes a restarted process a new stream, and with
``endpoint`` and ``seq`` it names every message once (duplicates and replays are dropped by
the receiver's sliding window, see ``wire.py``). ``stamp`` is when the datagram was sent.

========  =====  ==========================================================================
field     bytes  meaning
========  =====  ==========================================================================
magic     2      ``b"RL"``: anything else is foreign traffic and dropped
version   1      protocol version (2)
kind      1      :class:`Kind`
flags     1      :class:`Flags`
-         1      reserved (0)
count     2      number of fragments of the message (1 when it fits one datagram)
sender    8      random id of the sending process
seq       4      per-endpoint sequence number (wraps at 2**32)
topic     8      FNV-1a 64 hash of the topic or service name
type      4      FNV-1a 32 hash of the type name (mismatches are dropped, not decoded)
index     2      this fragment's index
endpoint  2      the sending endpoint's number within its process
total     4      the whole message's payload size
stamp     8      send time, integer nanoseconds since the epoch (sender's clock)
========  =====  ==========================================================================
"""

from __future__ import annotations

import enum
import struct
from typing import NamedTuple

MAGIC = b"RL"
VERSION = 2  # 2: the MAC trailer
HEADER = struct.Struct("<2sBBBxHQIQIHHIq")
HEADER_SIZE = HEADER.size
# Addressed datagrams (a service response, a history replay) start their payload with this:
# target process id, target endpoint, correlation (the request's sequence number)
ADDRESS = struct.Struct("<QHxxI")
ADDRESS_SIZE = ADDRESS.size

_FNV64_OFFSET = 0xCBF29CE484222325
_FNV64_PRIME = 0x100000001B3
_FNV32_OFFSET = 0x811C9DC5
_FNV32_PRIME = 0x01000193


class Kind(enum.IntEnum):
    """What a datagram carries."""

    DATA = 1  # a message on a topic
    REQUEST = 2  # a service request
    RESPONSE = 3  # a service response (addressed to the client)
    DISCOVERY = 4  # node announcements, graph queries, goodbyes
    REPLAY = 5  # transient-local history for one late subscriber (addressed)
    FAILURE = 6  # a server's answer that its callback failed (addressed; JSON, see node/service)


class Flags(enum.IntFlag):
    """Per-datagram flags."""

    NONE = 0
    ADDRESSED = 1  # the payload starts with an ADDRESS record
    LOCKSTEP = 2  # sent by a lock-stepped simulator: subscribers answer when they handled it
    BATCH = 4  # the payload is several small messages of one endpoint (see coalesce.py)
    SIGNED = 8  # the datagram ends with a MAC (see auth.py)
    SHM = 16  # the payload is a descriptor of a message in shared memory (see shm.py)


class Header(NamedTuple):
    """A decoded datagram header."""

    magic: bytes
    version: int
    kind: int
    flags: int
    # ``count`` and ``index`` are the wire's fragment fields; as NamedTuple fields they hide
    # tuple.count()/tuple.index(), which nothing calls on a Header.
    count: int  # type: ignore[assignment]
    sender: int
    seq: int
    topic: int
    type: int
    index: int  # type: ignore[assignment]
    endpoint: int
    total: int
    stamp: int


def topic_hash(name: str) -> int:
    """FNV-1a 64 of a topic or service name."""
    value = _FNV64_OFFSET
    for byte in name.encode():
        value = ((value ^ byte) * _FNV64_PRIME) & 0xFFFFFFFFFFFFFFFF
    return value


def type_hash(name: str) -> int:
    """FNV-1a 32 of a canonical type name."""
    value = _FNV32_OFFSET
    for byte in name.encode():
        value = ((value ^ byte) * _FNV32_PRIME) & 0xFFFFFFFF
    return value


def pack(
    kind: int,
    sender: int,
    seq: int,
    topic: int,
    type_: int,
    endpoint: int,
    total: int,
    stamp: int,
    *,
    flags: int = 0,
    count: int = 1,
    index: int = 0,
) -> bytes:
    """Pack one header."""
    return HEADER.pack(
        MAGIC, VERSION, kind, flags, count, sender, seq, topic, type_, index, endpoint, total, stamp
    )


def unpack(data: bytes | bytearray | memoryview) -> Header | None:
    """Unpack a header, or return None for foreign, truncated or future-version datagrams."""
    if len(data) < HEADER_SIZE or data[0:2] != MAGIC:
        return None
    header = Header(*HEADER.unpack_from(data))
    if header.version != VERSION or header.count == 0 or header.index >= header.count:
        return None
    return header
