"""The 48-byte datagram header: packing, validation, and the name hashes."""

from __future__ import annotations

import pytest

from rosl.bus import header as hdr
from rosl.bus.header import (
    ADDRESS,
    ADDRESS_SIZE,
    HEADER,
    HEADER_SIZE,
    MAGIC,
    VERSION,
    Flags,
    Header,
    Kind,
    pack,
    topic_hash,
    type_hash,
    unpack,
)

FIELDS = {
    "kind": Kind.RESPONSE,
    "sender": 0x0123456789ABCDEF,
    "seq": 0xFFFFFFFE,
    "topic": 0xFEDCBA9876543210,
    "type_": 0xDEADBEEF,
    "endpoint": 0xBEEF,
    "total": 0xFFFFFFF0,
    "stamp": 1_700_000_000_123_456_789,
}


def test_sizes_are_the_documented_ones() -> None:
    assert HEADER_SIZE == 48
    assert ADDRESS_SIZE == 16
    assert MAGIC == b"RL"
    assert VERSION == 2


def test_pack_unpack_round_trips_every_field() -> None:
    data = pack(**FIELDS, flags=Flags.ADDRESSED, count=7, index=6)
    assert len(data) == HEADER_SIZE
    assert data[:2] == b"RL"
    got = unpack(data)
    assert got == Header(
        magic=b"RL",
        version=2,
        kind=Kind.RESPONSE,
        flags=Flags.ADDRESSED,
        count=7,
        sender=FIELDS["sender"],
        seq=FIELDS["seq"],
        topic=FIELDS["topic"],
        type=FIELDS["type_"],
        index=6,
        endpoint=FIELDS["endpoint"],
        total=FIELDS["total"],
        stamp=FIELDS["stamp"],
    )


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("kind", int(Kind.DATA)),
        ("kind", int(Kind.REPLAY)),
        ("sender", 0),
        ("sender", 2**64 - 1),
        ("seq", 0),
        ("seq", 2**32 - 1),
        ("topic", 2**64 - 1),
        ("type_", 0),
        ("endpoint", 0),
        ("endpoint", 2**16 - 1),
        ("total", 0),
        ("total", 2**32 - 1),
        ("stamp", -1),
        ("stamp", 2**63 - 1),
    ],
)
def test_extreme_field_values_round_trip(field: str, value: int) -> None:
    fields = {**FIELDS, field: value}
    got = unpack(pack(**fields))
    assert got is not None
    name = "type" if field == "type_" else field
    assert getattr(got, name) == value
    assert (got.count, got.index, got.flags) == (1, 0, 0)


def test_defaults_are_one_unaddressed_fragment() -> None:
    got = unpack(pack(Kind.DATA, 1, 2, 3, 4, 5, 6, 7))
    assert got is not None
    assert (got.flags, got.count, got.index) == (0, 1, 0)


def test_unpack_accepts_bytearray_and_memoryview_with_payload_behind() -> None:
    data = pack(**FIELDS) + b"payload"
    for form in (bytearray(data), memoryview(data)):
        got = unpack(form)
        assert got is not None
        assert got.sender == FIELDS["sender"]


def test_maximum_count_and_last_index() -> None:
    got = unpack(pack(**FIELDS, count=0xFFFF, index=0xFFFE))
    assert got is not None
    assert (got.count, got.index) == (0xFFFF, 0xFFFE)


def _raw(**override: object) -> bytes:
    values = {
        "magic": MAGIC,
        "version": VERSION,
        "kind": 1,
        "flags": 0,
        "count": 1,
        "sender": 1,
        "seq": 1,
        "topic": 1,
        "type": 1,
        "index": 0,
        "endpoint": 1,
        "total": 0,
        "stamp": 0,
    }
    values.update(override)
    return HEADER.pack(*values.values())


@pytest.mark.parametrize(
    "data",
    [
        pytest.param(_raw(magic=b"XX"), id="foreign-magic"),
        pytest.param(_raw(magic=b"rl"), id="lowercase-magic"),
        pytest.param(b"RTPS" + bytes(60), id="rtps"),
        pytest.param(b"", id="empty"),
        pytest.param(b"R", id="one-byte"),
        pytest.param(_raw()[: HEADER_SIZE - 1], id="short-by-one"),
        pytest.param(_raw(version=0), id="version-0"),
        pytest.param(_raw(version=3), id="future-version"),
        pytest.param(_raw(version=255), id="version-255"),
        pytest.param(_raw(version=1), id="old-version"),
        pytest.param(_raw(count=0), id="count-0"),
        pytest.param(_raw(count=0, index=0), id="count-0-index-0"),
        pytest.param(_raw(count=1, index=1), id="index-equals-count"),
        pytest.param(_raw(count=3, index=7), id="index-beyond-count"),
        pytest.param(_raw(count=5, index=0xFFFF), id="index-max"),
    ],
)
def test_unpack_rejects_foreign_or_broken_headers(data: bytes) -> None:
    assert unpack(data) is None


def test_exactly_a_header_is_enough() -> None:
    assert unpack(_raw()) is not None


# Hashes are part of the wire format: another rosl version must compute the same ones.
KNOWN_TOPIC_HASHES = {
    "": 0xCBF29CE484222325,  # the FNV-1a 64 offset basis
    "a": 0xAF63DC4C8601EC8C,  # published FNV-1a test vector
    "foobar": 0x85944171F73967E8,  # published FNV-1a test vector
    "/chatter": 0xBFE1A1CFB386356B,
    "/rosout": 0xD46ADD98F57FDCEA,
    "@discovery": 0xDCAB316A1FCB296F,
}
KNOWN_TYPE_HASHES = {
    "": 0x811C9DC5,  # the FNV-1a 32 offset basis
    "a": 0xE40C292C,  # published FNV-1a test vector
    "foobar": 0xBF9CF968,  # published FNV-1a test vector
    "std_msgs/msg/String": 0x4745AF01,
    "rosl/discovery/1": 0x23D6D728,
}


@pytest.mark.parametrize(("name", "value"), KNOWN_TOPIC_HASHES.items())
def test_topic_hash_known_values(name: str, value: int) -> None:
    assert topic_hash(name) == value
    assert topic_hash(name) == topic_hash(name)


@pytest.mark.parametrize(("name", "value"), KNOWN_TYPE_HASHES.items())
def test_type_hash_known_values(name: str, value: int) -> None:
    assert type_hash(name) == value


def test_hashes_differ_for_different_names() -> None:
    names = ["/chatter", "/chatter2", "/Chatter", "chatter", "/a/b", "/b/a", "/rosout", "/"]
    assert len({topic_hash(n) for n in names}) == len(names)
    types = ["std_msgs/msg/String", "std_msgs/msg/Int32", "std_msgs/msg/string", "a/b/C"]
    assert len({type_hash(t) for t in types}) == len(types)


def test_hashes_fit_their_header_fields_and_use_utf8() -> None:
    for name in ["/ünïcödé", "/" + "x" * 1000]:
        assert 0 <= topic_hash(name) < 2**64
        assert 0 <= type_hash(name) < 2**32
    assert topic_hash("/ü") != topic_hash("/u")
    got = unpack(pack(Kind.DATA, 1, 1, topic_hash("/ü"), type_hash("a/msg/ü"), 1, 0, 0))
    assert got is not None
    assert got.topic == topic_hash("/ü")
    assert got.type == type_hash("a/msg/ü")


def test_address_record_round_trips() -> None:
    record = (2**64 - 1, 0xFFFF, 2**32 - 1)
    packed = ADDRESS.pack(*record)
    assert len(packed) == ADDRESS_SIZE
    assert ADDRESS.unpack(packed) == record


def test_module_exports_used_by_wire() -> None:
    assert hdr.HEADER.size == HEADER_SIZE
    assert {k.name for k in Kind} == {
        "DATA", "REQUEST", "RESPONSE", "DISCOVERY", "REPLAY", "FAILURE"
    }  # fmt: skip
