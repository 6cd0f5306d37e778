"""The domain key: created on first use, private, shared on purpose; and the MAC check."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import time
from typing import TYPE_CHECKING

import pytest

from rosl.bus import auth
from rosl.bus.errors import BusError
from rosl.bus.header import HEADER, MAGIC, VERSION, Flags, Kind
from rosl.bus.multicast import Addressing, MulticastTransport
from rosl.bus.wire import Reader, Writer
from tests.bus.helpers import Collector

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

TOPIC = "/auth_test"
TYPE = "std_msgs/msg/String"


# --- where the key comes from -------------------------------------------------------------------


def test_the_first_use_creates_a_private_key_and_later_uses_read_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROSL_HOME", str(tmp_path / "home"))
    first = auth.load(3, env={})
    second = auth.load(3, env={})
    assert first is not None
    assert second is not None
    key = tmp_path / "home" / "key"
    assert stat.S_IMODE(key.stat().st_mode) == 0o600
    assert stat.S_IMODE(key.parent.stat().st_mode) == 0o700
    assert len(key.read_text().strip()) == 64  # 32 random bytes, hex
    assert first.fingerprint == second.fingerprint
    assert first.source == str(key)
    assert first.mac(b"datagram") == second.mac(b"datagram")
    assert not list(key.parent.glob(".key.*"))  # no draft left behind


def test_processes_racing_to_create_the_key_all_get_the_same_one(tmp_path: Path) -> None:
    env = {**os.environ, "ROSL_HOME": str(tmp_path / "race")}
    env.pop("ROSL_KEY", None)
    env.pop("ROSL_KEY_FILE", None)
    code = "from rosl.bus import auth; print(auth.load(0).fingerprint)"
    children = [
        subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE, text=True)
        for _ in range(6)
    ]
    prints = set()
    try:
        for child in children:
            out, _ = child.communicate(timeout=60)
            assert child.returncode == 0
            prints.add(out.strip())
    finally:
        for child in children:
            if child.poll() is None:
                child.kill()
                child.wait(5)
    assert len(prints) == 1


def test_a_key_file_others_can_read_is_refused_in_one_line(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROSL_HOME", str(tmp_path))
    key = tmp_path / "key"
    key.write_text("secret\n")
    key.chmod(0o644)
    with pytest.raises(BusError) as caught:
        auth.load(0, env={})
    message = str(caught.value)
    assert str(key) in message
    assert "chmod 600" in message
    assert "\n" not in message


def test_an_empty_or_missing_named_key_file_is_refused(tmp_path: Path) -> None:
    empty = tmp_path / "empty"
    empty.write_text("\n")
    with pytest.raises(BusError, match="empty"):
        auth.load(0, env={"ROSL_KEY_FILE": str(empty)})
    with pytest.raises(BusError, match="cannot read the key file"):
        auth.load(0, env={"ROSL_KEY_FILE": str(tmp_path / "nowhere")})


def test_a_shared_key_is_the_same_for_everyone_and_none_turns_it_off(tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    shared.write_text("team secret\n")
    shared.chmod(0o640)  # a group-readable shared key is fine
    by_file = auth.load(4, env={"ROSL_KEY_FILE": str(shared)})
    by_text = auth.load(4, env={"ROSL_KEY": "team secret"})
    other = auth.load(4, env={"ROSL_KEY": "another secret"})
    assert by_file is not None
    assert by_text is not None
    assert other is not None
    assert by_file.mac(b"x") == by_text.mac(b"x") != other.mac(b"x")
    assert auth.load(4, env={"ROSL_KEY": "none"}) is None
    assert auth.load(4, env={"ROSL_KEY": "NONE", "ROSL_KEY_FILE": str(shared)}) is None


def test_the_key_of_one_domain_does_not_verify_in_another() -> None:
    one = auth.load(1, env={"ROSL_KEY": "k"})
    two = auth.load(2, env={"ROSL_KEY": "k"})
    assert one is not None
    assert two is not None
    for size in (10, auth.SMALL, auth.SMALL + 1, 60_000):  # both MACs
        body = os.urandom(size)
        assert one.mac(body) != two.mac(body)
        assert one.verify(body + one.mac(body))
        assert not two.verify(body + one.mac(body))
        assert one.mac_parts([body[:7], body[7:]]) == one.mac(body)


# --- the MAC check on real sockets ----------------------------------------------------------------


class Pair:
    """Senders under two keys and none, and a keyed reader on one socket."""

    def __init__(self, domain: int) -> None:
        self.alice = auth.Auth(b"alice", domain, "test")
        self.mallory = auth.Auth(b"mallory", domain, "test")
        self.tx_alice = MulticastTransport(Addressing(domain), self.alice)
        self.tx_mallory = MulticastTransport(Addressing(domain), self.mallory)
        self.tx_none = MulticastTransport(Addressing(domain), None)
        self.rx = MulticastTransport(Addressing(domain), None)
        self.reader = Reader(self.alice)
        self.reader.want_all = True
        self.writer = Writer(self.tx_alice, 0xA11CE, 1, TOPIC, TYPE)
        self.collector = Collector(self.reader, self.rx.open(self.writer.channel))

    def close(self) -> None:
        self.collector.stop()
        for transport in (self.tx_alice, self.tx_mallory, self.tx_none, self.rx):
            transport.close()


@pytest.fixture
def pair(domain_id: int) -> Iterator[Pair]:
    p = Pair(domain_id)
    try:
        yield p
    finally:
        p.close()


def test_only_datagrams_under_the_readers_key_are_delivered(pair: Pair) -> None:
    strangers = [
        Writer(pair.tx_mallory, 0xBAD, 1, TOPIC, TYPE),
        Writer(pair.tx_none, 0xBAD2, 1, TOPIC, TYPE),
    ]
    for size in (5, 3000, 70_000):  # small, big and fragmented
        for writer in strangers:
            writer.send(b"s" * size)
        pair.writer.send(b"a" * size)
    got = pair.collector.wait_count(3, timeout=10.0)
    time.sleep(0.2)
    got = pair.collector.snapshot()
    assert [(d.sender, len(d.payload)) for d in got] == [
        (0xA11CE, 5), (0xA11CE, 3000), (0xA11CE, 70_000)
    ]  # fmt: skip
    assert pair.collector.wait_for(lambda _: pair.reader.forged == 4)  # 1 + 1 + 2 fragments
    assert pair.reader.unsigned == 4
    assert pair.reader.received() == 3


def test_plain_messages_of_every_size_are_signed_and_checked_under_the_key(pair: Pair) -> None:
    stranger = Writer(pair.tx_mallory, 0xBAD, 1, TOPIC, TYPE)
    sizes = (0, 5, 1999, 2000, 2001, 2047, 2048, 3000, 70_000)  # 2000 + the header: auth.SMALL
    for size in sizes:
        stranger.send_plain(b"s" * size)
        pair.writer.send_plain(b"a" * size)
    got = pair.collector.wait_count(len(sizes), timeout=10.0)
    assert [(d.sender, bytes(d.payload)) for d in got] == [(0xA11CE, b"a" * n) for n in sizes]
    assert pair.collector.wait_for(lambda _: pair.reader.forged == len(sizes) + 1)  # 2 fragments
    assert pair.reader.received() == len(sizes)


def test_a_tampered_datagram_is_forged_even_with_the_signed_flag(pair: Pair) -> None:
    payload = b"hello"
    head = HEADER.pack(
        MAGIC, VERSION, Kind.DATA, Flags.SIGNED, 1, 0xA11CE, 1, pair.writer.topic,
        pair.writer.type, 0, 1, len(payload), time.time_ns(),
    )  # fmt: skip
    good = head + payload + pair.alice.mac(head + payload)
    tampered = bytearray(good)
    tampered[-17] ^= 1  # the last payload byte
    pair.tx_none.send(pair.writer.channel, [bytes(tampered)])
    pair.tx_none.send(pair.writer.channel, [good[:-1]])  # a cut MAC
    pair.tx_none.send(pair.writer.channel, [good])
    got = pair.collector.wait_count(1)
    assert [bytes(d.payload) for d in got] == [payload]
    assert pair.collector.wait_for(lambda _: pair.reader.forged == 2)


def test_a_reader_without_a_key_takes_signed_and_unsigned_datagrams(
    pair: Pair, domain_id: int
) -> None:
    open_reader = Reader(None)
    open_reader.want_all = True
    rx = MulticastTransport(Addressing(domain_id), None)
    collector = Collector(open_reader, rx.open(pair.writer.channel))
    try:
        pair.writer.send(b"signed")
        Writer(pair.tx_none, 0xBAD2, 1, TOPIC, TYPE).send(b"plain")
        got = collector.wait_count(2)
        assert sorted(bytes(d.payload) for d in got) == [b"plain", b"signed"]
        assert all(d.flags == 0 for d in got)  # SIGNED is a wire detail
    finally:
        collector.stop()
        rx.close()


def test_a_command_with_an_unsafe_key_file_fails_in_one_line(
    tmp_path: Path, domain_id: int
) -> None:
    home = tmp_path / "rosl-home"
    home.mkdir()
    (home / "key").write_text("secret\n")
    (home / "key").chmod(0o644)
    env = {**os.environ, "ROSL_HOME": str(home)}
    env.pop("ROSL_KEY", None)
    env.pop("ROSL_KEY_FILE", None)
    result = subprocess.run(
        [sys.executable, "-m", "rosl", "topic", "list"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        stdin=subprocess.DEVNULL,
    )
    assert result.returncode != 0
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert str(home / "key") in lines[0]
    assert "chmod 600" in lines[0]
