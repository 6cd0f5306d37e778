"""rmw_zenoh's wire format: key expressions, liveliness tokens, QoS strings, attachments, GIDs.

Written from ros2/rmw_zenoh's ``docs/design.md`` and ``liveliness_utils.cpp`` (Jazzy and
later), so that rosl and a ROS 2 node using ``rmw_zenoh_cpp`` name the same things the same
way. Pure functions over strings and bytes: no Zenoh session here.

* data and service key: ``<domain>/<name without outer slashes>/<DDS type>/<type hash>``,
  e.g. ``0/chatter/std_msgs::msg::dds_::String_/RIHS01_df66...``;
* liveliness token: ``@ros2_lv/<domain>/<zid>/<nid>/<eid>/<NN|MP|MS|SS|SC>/<enclave>/<ns>/
  <node>[/<name>/<DDS type>/<type hash>/<qos>]`` with every ``/`` inside a field written
  ``%`` (an empty namespace or enclave, ``/``, is therefore ``%``);
* QoS: ``rel:dur:hist,depth:dl_s,dl_ns:ls_s,ls_ns:liv,lease_s,lease_ns`` where a value equal
  to rmw_zenoh's default (reliable, volatile, keep last 42, infinite times, automatic) is
  left empty;
* attachment (every put, get and reply): int64 sequence number, int64 source time (ns), both
  little endian, then the 16-byte GID as a Zenoh-serialized sequence (a one-byte length, 16);
* GID: XXH3-128 of the entity's liveliness key expression, low 64 bits first, little endian.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

import xxhash

ADMIN_SPACE = "@ros2_lv"
NODE, PUBLISHER, SUBSCRIPTION, SERVER, CLIENT = "NN", "MP", "MS", "SS", "SC"
ENTITY_KINDS = (NODE, PUBLISHER, SUBSCRIPTION, SERVER, CLIENT)
GID_SIZE = 16
ATTACHMENT = struct.Struct("<qqB16s")
ATTACHMENT_SIZE = ATTACHMENT.size  # 33
NO_TYPE_HASH = "TypeHashNotSupported"  # what Humble builds write

# rmw's enum values (rmw/types.h)
RELIABILITY = {"SYSTEM_DEFAULT": 0, "RELIABLE": 1, "BEST_EFFORT": 2, "UNKNOWN": 3,
               "BEST_AVAILABLE": 4}  # fmt: skip
DURABILITY = {"SYSTEM_DEFAULT": 0, "TRANSIENT_LOCAL": 1, "VOLATILE": 2, "UNKNOWN": 3,
              "BEST_AVAILABLE": 4}  # fmt: skip
HISTORY = {"SYSTEM_DEFAULT": 0, "KEEP_LAST": 1, "KEEP_ALL": 2, "UNKNOWN": 3}
LIVELINESS = {"SYSTEM_DEFAULT": 0, "AUTOMATIC": 1, "MANUAL_BY_TOPIC": 3, "UNKNOWN": 4,
              "BEST_AVAILABLE": 5}  # fmt: skip
INFINITE = (9223372036, 854775807)  # RMW_DURATION_INFINITE as (s, ns)


@dataclass(frozen=True, slots=True)
class Qos:
    """An rmw QoS profile as rmw_zenoh writes it into tokens (enum numbers, (s, ns) times)."""

    reliability: int = 1
    durability: int = 2
    history: int = 1
    depth: int = 42
    deadline: tuple[int, int] = INFINITE
    lifespan: tuple[int, int] = INFINITE
    liveliness: int = 1
    lease: tuple[int, int] = INFINITE

    @classmethod
    def from_words(cls, words: dict[str, object]) -> Qos:
        """From rosl's QoS words (``QoSProfile.words()``); system defaults become rmw_zenoh's."""
        reliability = RELIABILITY.get(str(words.get("reliability", "")).upper(), 1)
        durability = DURABILITY.get(str(words.get("durability", "")).upper(), 2)
        history = HISTORY.get(str(words.get("history", "")).upper(), 1)
        liveliness = LIVELINESS.get(str(words.get("liveliness", "")).upper(), 1)
        depth = int(str(words.get("depth", 0) or 0))
        return cls(
            reliability or 1, durability or 2, history or 1, depth or 42,
            liveliness=liveliness or 1,
        )  # fmt: skip

    def words(self) -> dict[str, object]:
        """Rosl's QoS words for this profile (for the graph)."""
        return {
            "reliability": _name(RELIABILITY, self.reliability),
            "durability": _name(DURABILITY, self.durability),
            "history": _name(HISTORY, self.history),
            "depth": self.depth,
            "liveliness": _name(LIVELINESS, self.liveliness),
        }


DEFAULT_QOS = Qos()


def _name(table: dict[str, int], value: int) -> str:
    for key, number in table.items():
        if number == value:
            return key
    return "UNKNOWN"


def qos_string(qos: Qos) -> str:
    """The QoS field of a liveliness token (``::,10:,:,:,,`` for depth 10, else defaults)."""
    d = DEFAULT_QOS

    def part(value: int, default: int) -> str:
        return "" if value == default else str(value)

    return (
        f"{part(qos.reliability, d.reliability)}:{part(qos.durability, d.durability)}:"
        f"{part(qos.history, d.history)},{part(qos.depth, d.depth)}:"
        f"{part(qos.deadline[0], d.deadline[0])},{part(qos.deadline[1], d.deadline[1])}:"
        f"{part(qos.lifespan[0], d.lifespan[0])},{part(qos.lifespan[1], d.lifespan[1])}:"
        f"{part(qos.liveliness, d.liveliness)},{part(qos.lease[0], d.lease[0])},"
        f"{part(qos.lease[1], d.lease[1])}"
    )


def parse_qos(text: str) -> Qos:
    """Read a token's QoS field; raises ValueError when it is malformed."""
    parts = text.split(":")
    if len(parts) < 6:
        raise ValueError(f"QoS {text!r} has {len(parts)} of 6 fields")
    history, deadline, lifespan, liveliness = (p.split(",") for p in parts[2:6])
    if len(history) < 2 or len(deadline) < 2 or len(lifespan) < 2 or len(liveliness) < 3:
        raise ValueError(f"QoS {text!r} lacks a component")
    d = DEFAULT_QOS

    def number(value: str, default: int) -> int:
        return default if value == "" else int(value)

    return Qos(
        number(parts[0], d.reliability),
        number(parts[1], d.durability),
        number(history[0], d.history),
        number(history[1], d.depth),
        (number(deadline[0], d.deadline[0]), number(deadline[1], d.deadline[1])),
        (number(lifespan[0], d.lifespan[0]), number(lifespan[1], d.lifespan[1])),
        number(liveliness[0], d.liveliness),
        (number(liveliness[1], d.lease[0]), number(liveliness[2], d.lease[1])),
    )


def mangle(name: str) -> str:
    """A name as one key-expression chunk: every ``/`` becomes ``%``."""
    return name.replace("/", "%")


def demangle(chunk: str) -> str:
    """The inverse of :func:`mangle`."""
    return chunk.replace("%", "/")


def dds_type(type_name: str) -> str:
    """``std_msgs/msg/String`` → ``std_msgs::msg::dds_::String_`` (the DDS name of a type)."""
    package, kind, name = type_name.split("/")
    return f"{package}::{kind}::dds_::{name}_"


def ros_type(dds_name: str) -> str:
    """``std_msgs::msg::dds_::String_`` → ``std_msgs/msg/String``; ValueError otherwise."""
    parts = dds_name.split("::")
    if len(parts) != 4 or parts[2] != "dds_" or not parts[3].endswith("_"):
        raise ValueError(f"{dds_name!r} is not a DDS type name")
    return f"{parts[0]}/{parts[1]}/{parts[3][:-1]}"


def topic_key(domain: int, name: str, type_name: str, type_hash: str) -> str:
    """The key expression of a topic's data or of a service's queries."""
    return f"{domain}/{name.strip('/')}/{dds_type(type_name)}/{type_hash}"


def humble_key(key: str) -> str:
    """A data key as ROS 2 Humble's rmw_zenoh writes it: ``TypeHashNotSupported`` as hash."""
    return f"{key.rsplit('/', 1)[0]}/{NO_TYPE_HASH}"


@dataclass(frozen=True, slots=True)
class TopicKey:
    """A data key expression, read back."""

    domain: int
    name: str  # fully qualified, with its leading slash
    type: str  # canonical ROS type name
    type_hash: str


def parse_topic_key(key: str) -> TopicKey:
    """Read ``<domain>/<name...>/<DDS type>/<hash>``; raises ValueError otherwise."""
    parts = key.split("/")
    if len(parts) < 4:
        raise ValueError(f"{key!r} is not a ROS 2 data key")
    return TopicKey(int(parts[0]), "/" + "/".join(parts[1:-2]), ros_type(parts[-2]), parts[-1])


@dataclass(frozen=True, slots=True)
class Entity:
    """One liveliness token: a node, or an endpoint of one."""

    domain: int
    zid: str
    nid: str
    eid: str
    kind: str  # one of ENTITY_KINDS
    enclave: str
    namespace: str
    node: str
    name: str = ""  # topic or service (endpoints only)
    type: str = ""  # canonical ROS type (endpoints only)
    type_hash: str = ""
    qos: Qos = field(default=DEFAULT_QOS)

    @property
    def keyexpr(self) -> str:
        """The token's key expression."""
        return liveliness_key(self)

    @property
    def gid(self) -> bytes:
        """The 16-byte GID rmw_zenoh derives from the token."""
        return gid_of(self.keyexpr)


def liveliness_key(entity: Entity) -> str:
    """The liveliness key expression of an entity, as rmw_zenoh's ``Entity`` builds it."""
    parts = [
        ADMIN_SPACE, str(entity.domain), entity.zid, entity.nid, entity.eid, entity.kind,
        mangle(entity.enclave or "/"), mangle(entity.namespace or "/"), mangle(entity.node),
    ]  # fmt: skip
    if entity.kind != NODE:
        parts += [
            mangle(entity.name), mangle(dds_type(entity.type)), mangle(entity.type_hash),
            qos_string(entity.qos),
        ]  # fmt: skip
    return "/".join(parts)


def parse_liveliness(key: str) -> Entity:
    """Read a liveliness token back; raises ValueError for anything malformed."""
    parts = key.split("/")
    if len(parts) < 9 or any(not p for p in parts) or parts[0] != ADMIN_SPACE:
        raise ValueError(f"{key!r} is not an rmw_zenoh liveliness token")
    kind = parts[5]
    if kind not in ENTITY_KINDS:
        raise ValueError(f"{key!r}: unknown entity kind {kind!r}")
    base = (int(parts[1]), parts[2], parts[3], parts[4], kind, demangle(parts[6]),
            demangle(parts[7]), demangle(parts[8]))  # fmt: skip
    if kind == NODE:
        return Entity(*base)
    if len(parts) < 13:
        raise ValueError(f"{key!r}: an endpoint token needs 13 fields")
    return Entity(
        *base, demangle(parts[9]), ros_type(demangle(parts[10])), demangle(parts[11]),
        parse_qos(parts[12]),
    )  # fmt: skip


def gid_of(keyexpr: str) -> bytes:
    """rmw_zenoh's GID of an entity: XXH3-128 of its liveliness key (low half first)."""
    digest = xxhash.xxh3_128_intdigest(keyexpr.encode())
    return digest.to_bytes(GID_SIZE, "little")


def gid_text(gid: bytes) -> str:
    """A GID as ``ros2 topic info -v`` prints it (dotted hex)."""
    return ".".join(f"{b:02x}" for b in gid)


def encode_attachment(sequence: int, stamp_ns: int, gid: bytes) -> bytes:
    """The attachment of a put, get or reply."""
    if len(gid) != GID_SIZE:
        raise ValueError(f"a GID has {GID_SIZE} bytes, not {len(gid)}")
    return ATTACHMENT.pack(sequence, stamp_ns, GID_SIZE, gid)


def decode_attachment(data: bytes | bytearray | memoryview) -> tuple[int, int, bytes]:
    """(sequence number, source time ns, GID) of an attachment; ValueError when malformed."""
    if len(data) != ATTACHMENT_SIZE:
        raise ValueError(f"an attachment has {ATTACHMENT_SIZE} bytes, not {len(data)}")
    sequence, stamp, length, gid = ATTACHMENT.unpack(data)
    if length != GID_SIZE:
        raise ValueError(f"the GID's length is {length}, not {GID_SIZE}")
    return sequence, stamp, gid
