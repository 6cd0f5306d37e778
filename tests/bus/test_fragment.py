"""Splitting messages into fragments and reassembling them (no network)."""

from __future__ import annotations

import mmap
import random

import pytest

from rosl.bus.auth import MAC_SIZE
from rosl.bus.fragment import (
    LAZY_ABOVE,
    MAX_AGE_NS,
    MAX_MESSAGE_SIZE,
    PARTIAL_OVERHEAD,
    Reassembler,
    split,
)
from rosl.bus.header import HEADER_SIZE, MAGIC, VERSION, Header, Kind

CHUNK = 100  # small chunks keep the unit tests readable
REAL_CHUNK = 65000 - HEADER_SIZE - MAC_SIZE  # what a loopback Writer (signing) uses


def payload_of(size: int, seed: int = 0) -> bytes:
    return random.Random(seed).randbytes(size)


def header(
    *,
    total: int,
    count: int,
    index: int,
    seq: int = 1,
    sender: int = 0xABC,
    endpoint: int = 3,
    kind: int = Kind.DATA,
) -> Header:
    return Header(
        MAGIC, VERSION, kind, 0, count, sender, seq, 0x7077, 0x7E, index, endpoint, total, 0
    )


def fragments(payload: bytes, chunk: int = CHUNK, **key: int) -> list[tuple[Header, memoryview]]:
    """The (header, payload view) pairs a Writer would send for ``payload``."""
    return [
        (header(total=len(payload), count=count, index=index, **key), view)
        for index, count, view in split(payload, chunk)
    ]


def feed(
    reassembler: Reassembler, frags: list[tuple[Header, memoryview]], now: int = 0
) -> list[bytes]:
    """Add fragments in the given order; return every completed message (as bytes)."""
    done = []
    for head, view in frags:
        whole = reassembler.add(head, view, now)
        if whole is not None:
            done.append(bytes(whole))
    return done


# --- split ------------------------------------------------------------------------------------


@pytest.mark.parametrize("chunk", [CHUNK, REAL_CHUNK])
@pytest.mark.parametrize(
    ("size_of", "expected_count"),
    [
        (lambda c: 0, 1),
        (lambda c: 1, 1),
        (lambda c: c - 1, 1),
        (lambda c: c, 1),
        (lambda c: c + 1, 2),
        (lambda c: 2 * c - 1, 2),
        (lambda c: 3 * c, 3),
        (lambda c: 3 * c + 1, 4),
    ],
    ids=["0", "1", "chunk-1", "chunk", "chunk+1", "2chunk-1", "3chunk", "3chunk+1"],
)
def test_split_sizes_around_the_chunk_boundary(size_of, expected_count: int, chunk: int) -> None:
    size = size_of(chunk)
    payload = payload_of(size)
    parts = list(split(payload, chunk))
    assert len(parts) == expected_count
    assert [index for index, _, _ in parts] == list(range(expected_count))
    assert all(count == expected_count for _, count, _ in parts)
    for _, _, view in parts[:-1]:
        assert len(view) == chunk
    last = parts[-1][2]
    assert len(last) == size - chunk * (expected_count - 1)
    assert b"".join(bytes(view) for _, _, view in parts) == payload
    for index, _, view in parts:
        assert isinstance(view, memoryview)
        assert bytes(view) == payload[index * chunk : (index + 1) * chunk]


def test_split_makes_views_not_copies() -> None:
    payload = bytearray(payload_of(3 * CHUNK + 5))
    parts = list(split(payload, CHUNK))
    payload[CHUNK] ^= 0xFF  # the second fragment sees the change: it is a view
    assert parts[1][2][0] == payload[CHUNK]
    assert all(view.obj is payload for _, _, view in parts)


def test_split_accepts_memoryview_input() -> None:
    payload = payload_of(250)
    parts = list(split(memoryview(payload)[10:], CHUNK))
    assert [len(v) for _, _, v in parts] == [100, 100, 40]
    assert b"".join(bytes(v) for _, _, v in parts) == payload[10:]


# --- reassembly -------------------------------------------------------------------------------


def test_single_fragment_message_completes_at_once() -> None:
    r = Reassembler()
    got = feed(r, fragments(b"hello"))
    assert got == [b"hello"]
    assert r.pending == 0


def test_empty_message_completes() -> None:
    r = Reassembler()
    assert feed(r, fragments(b"")) == [b""]


@pytest.mark.parametrize("order", ["in-order", "reversed", "shuffled", "last-first"])
@pytest.mark.parametrize("size", [CHUNK + 1, 3 * CHUNK, 10 * CHUNK + 7])
def test_reassembles_in_any_order(order: str, size: int) -> None:
    payload = payload_of(size, seed=size)
    frags = fragments(payload)
    if order == "reversed":
        frags.reverse()
    elif order == "shuffled":
        random.Random(size).shuffle(frags)
    elif order == "last-first":
        frags = [frags[-1], *frags[:-1]]
    r = Reassembler()
    results = [r.add(h, v, 0) for h, v in frags]
    assert all(x is None for x in results[:-1]), "completed before every fragment arrived"
    assert results[-1] is not None
    assert bytes(results[-1]) == payload
    assert r.pending == 0
    assert (r.incomplete, r.malformed) == (0, 0)


def test_duplicates_do_not_complete_early_or_corrupt() -> None:
    payload = payload_of(5 * CHUNK + 3, seed=7)
    frags = fragments(payload)
    rng = random.Random(3)
    # every fragment but the last twice (shuffled), then the last one: completes exactly once
    doubled = frags[:-1] * 2
    rng.shuffle(doubled)
    r = Reassembler()
    assert feed(r, doubled) == []
    assert r.pending == 1
    assert feed(r, [frags[-1]]) == [payload]
    assert r.pending == 0
    assert (r.incomplete, r.malformed) == (0, 0)


def test_duplicate_with_different_content_does_not_overwrite() -> None:
    payload = payload_of(3 * CHUNK, seed=1)
    frags = fragments(payload)
    r = Reassembler()
    assert feed(r, frags[:1]) == []
    forged = memoryview(bytes(CHUNK))
    assert r.add(frags[0][0], forged, 0) is None
    assert feed(r, frags[1:]) == [payload]


def test_interleaved_messages_of_different_streams_both_complete() -> None:
    a = payload_of(4 * CHUNK, seed=1)
    b = payload_of(4 * CHUNK + 9, seed=2)
    fa = fragments(a, sender=1)
    fb = fragments(b, sender=2)
    mixed = [f for pair in zip(fa, fb, strict=False) for f in pair] + fb[len(fa) :]
    r = Reassembler()
    assert sorted(feed(r, mixed)) == sorted([a, b])
    assert r.incomplete == 0


def test_same_seq_different_kind_or_endpoint_are_different_messages() -> None:
    a = payload_of(2 * CHUNK, seed=1)
    b = payload_of(2 * CHUNK, seed=2)
    c = payload_of(2 * CHUNK, seed=3)
    fa = fragments(a, seq=9, kind=Kind.DATA)
    fb = fragments(b, seq=9, kind=Kind.REPLAY)
    fc = fragments(c, seq=9, endpoint=99)
    r = Reassembler()
    got = feed(r, [fa[0], fb[0], fc[0], fa[1], fb[1], fc[1]])
    assert got == [a, b, c]
    assert r.incomplete == 0


def test_big_messages_use_an_mmap_buffer_that_bytes_can_read() -> None:
    payload = payload_of(LAZY_ABOVE + 1, seed=4)
    frags = fragments(payload, REAL_CHUNK)
    random.Random(0).shuffle(frags)
    r = Reassembler()
    whole = None
    for h, v in frags:
        whole = r.add(h, v, 0) or whole
    assert isinstance(whole, mmap.mmap)
    assert len(whole) == len(payload)
    assert bytes(whole) == payload
    assert bytes(memoryview(whole)[-10:]) == payload[-10:]


def test_messages_up_to_one_mib_use_a_bytearray() -> None:
    payload = payload_of(LAZY_ABOVE, seed=5)
    r = Reassembler()
    whole = None
    for h, v in fragments(payload, REAL_CHUNK):
        whole = r.add(h, v, 0) or whole
    assert isinstance(whole, bytearray)
    assert whole == payload


# --- incomplete messages ----------------------------------------------------------------------


def test_expire_drops_and_counts_a_stale_partial() -> None:
    frags = fragments(payload_of(3 * CHUNK))
    r = Reassembler(max_age_ns=1000)
    feed(r, frags[:2], now=5000)
    assert r.pending == 1
    r.expire(5000 + 1000)  # exactly max_age old: still waiting
    assert (r.pending, r.incomplete) == (1, 0)
    r.expire(5000 + 1001)
    assert (r.pending, r.incomplete) == (0, 1)
    r.expire(10**12)  # nothing left to drop: counted once
    assert r.incomplete == 1


def test_expire_without_a_time_uses_the_clock() -> None:
    r = Reassembler()
    assert r.max_age_ns == MAX_AGE_NS
    feed(r, fragments(payload_of(2 * CHUNK))[:1], now=0)  # started at the epoch: ancient
    r.expire()
    assert (r.pending, r.incomplete) == (0, 1)


def test_expire_keeps_fresh_partials_and_completed_messages_are_not_counted() -> None:
    r = Reassembler(max_age_ns=1000)
    assert feed(r, fragments(payload_of(2 * CHUNK), seq=1), now=0) != []
    feed(r, fragments(payload_of(2 * CHUNK), seq=2)[:1], now=900)
    r.expire(1500)
    assert (r.pending, r.incomplete) == (1, 0)


def test_a_newer_message_from_the_same_stream_evicts_the_older_partial() -> None:
    old = fragments(payload_of(3 * CHUNK, seed=1), seq=1)
    new_payload = payload_of(3 * CHUNK, seed=2)
    new = fragments(new_payload, seq=2)
    r = Reassembler()
    feed(r, old[:2])
    assert r.pending == 1
    assert feed(r, new[:1]) == []
    assert (r.pending, r.incomplete) == (1, 1)  # the old one is gone, and counted
    assert feed(r, new[1:]) == [new_payload]
    assert (r.pending, r.incomplete) == (0, 1)


@pytest.mark.parametrize(
    "other",
    [{"sender": 0xDEF}, {"endpoint": 4}, {"kind": Kind.REPLAY}],
    ids=["other-sender", "other-endpoint", "other-kind"],
)
def test_other_streams_do_not_evict(other: dict[str, int]) -> None:
    first_payload = payload_of(2 * CHUNK, seed=1)
    first = fragments(first_payload, seq=1)
    second = fragments(payload_of(2 * CHUNK, seed=2), seq=2, **other)
    r = Reassembler()
    feed(r, first[:1])
    feed(r, second[:1])
    assert (r.pending, r.incomplete) == (2, 0)
    assert feed(r, first[1:]) == [first_payload]


# --- malformed fragments ----------------------------------------------------------------------


def test_claims_beyond_the_maximum_message_size_are_malformed() -> None:
    r = Reassembler()
    h = header(total=MAX_MESSAGE_SIZE + 1, count=2**16 - 1, index=0)
    assert r.add(h, memoryview(bytes(REAL_CHUNK)), 0) is None
    h = header(total=2**32 - 1, count=2, index=1)
    assert r.add(h, memoryview(bytes(10)), 0) is None
    assert r.malformed == 2
    assert r.pending == 0


def test_fragment_longer_than_the_total_is_malformed() -> None:
    r = Reassembler()
    assert r.add(header(total=10, count=2, index=1), memoryview(bytes(11)), 0) is None
    assert r.add(header(total=10, count=2, index=0, seq=2), memoryview(bytes(11)), 0) is None
    assert r.malformed == 2
    assert r.pending == 0


def test_non_last_fragment_too_short_for_the_total_is_malformed() -> None:
    r = Reassembler()
    # 3 fragments of 10 bytes cannot carry 100 bytes
    assert r.add(header(total=100, count=3, index=0), memoryview(bytes(10)), 0) is None
    assert r.malformed == 1
    assert r.pending == 0


def test_inconsistent_count_or_total_for_the_same_message_is_malformed() -> None:
    payload = payload_of(3 * CHUNK)
    frags = fragments(payload)
    r = Reassembler()
    feed(r, frags[:1])
    h1, v1 = frags[1]
    assert r.add(h1._replace(count=4), v1, 0) is None
    assert r.add(h1._replace(total=3 * CHUNK + 50), v1, 0) is None
    assert r.malformed == 2
    assert feed(r, frags[1:]) == [payload]  # the real fragments still complete it


def test_offset_beyond_the_total_is_malformed() -> None:
    r = Reassembler()
    # 250 bytes in 3 fragments: a middle fragment of 200 bytes would end at 400
    h = header(total=250, count=3, index=1)
    assert r.add(h, memoryview(bytes(200)), 0) is None
    assert r.malformed == 1


def test_malformed_fragments_never_raise() -> None:
    rng = random.Random(1234)
    r = Reassembler(budget=4 * 1024 * 1024)
    for _ in range(3000):
        count = rng.choice([1, 2, 3, rng.randrange(1, 2**16)])
        total = rng.choice(
            [0, 1, rng.randrange(0, 4096), rng.randrange(0, 2**32), MAX_MESSAGE_SIZE]
        )
        h = header(
            total=total,
            count=count,
            index=rng.randrange(count),
            seq=rng.randrange(4),
            sender=rng.randrange(3),
            endpoint=rng.randrange(2),
            kind=rng.choice(list(Kind)),
        )
        view = memoryview(rng.randbytes(rng.choice([0, 1, rng.randrange(0, 2000)])))
        whole = r.add(h, view, rng.randrange(0, 10**10))
        if whole is not None:
            assert len(whole) == total
        if rng.random() < 0.01:
            r.expire(rng.randrange(0, 10**10))
    assert r.malformed > 0


# --- memory cap -------------------------------------------------------------------------------


def test_pending_bytes_stay_under_the_cap() -> None:
    total = 1000
    cap = 10 * (total + PARTIAL_OVERHEAD)
    r = Reassembler(budget=cap)
    for sender in range(200):
        frags = fragments(payload_of(total, seed=sender), sender=sender)
        feed(r, frags[:1])  # a partial per sender, never completed
        assert r.held <= cap
    assert r.pending == 10
    assert r.held <= cap
    assert r.evicted == 200 - 10


def test_cap_evicts_the_oldest_partial_first() -> None:
    total = 1000
    r = Reassembler(budget=3 * (total + PARTIAL_OVERHEAD))
    payloads = {s: payload_of(total, seed=s) for s in range(5)}
    frags = {s: fragments(payloads[s], sender=s) for s in payloads}
    for s in payloads:
        feed(r, frags[s][:1])
    assert (r.pending, r.evicted) == (3, 2)
    # senders 0 and 1 were evicted; 2, 3, 4 can still complete
    for s in (2, 3, 4):
        assert feed(r, frags[s][1:]) == [payloads[s]]
    assert feed(r, frags[0][1:]) == []  # its first fragment is gone


def test_completed_messages_free_their_share_of_the_cap() -> None:
    total = 1000
    r = Reassembler(budget=2 * (total + PARTIAL_OVERHEAD))
    for seq in range(50):
        payload = payload_of(total, seed=seq)
        assert feed(r, fragments(payload, sender=seq)) == [payload]
    assert (r.pending, r.incomplete, r.evicted, r.held) == (0, 0, 0, 0)
