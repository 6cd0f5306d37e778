"""The shared-memory path for large messages: rings in /dev/shm, descriptors on the bus.

Real processes on the test's domain: nodes publishing large and small messages, a writer
that fills its ring while the subscriber does not read (a slow subscriber), and one killed
with SIGKILL (a crashed publisher, whose ring the next process removes).
"""

from __future__ import annotations

import os
import shutil
import signal
import stat
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from rosl.bus.header import topic_hash
from rosl.bus.multicast import Addressing, MulticastTransport
from rosl.bus.shm import DIRECTORY
from rosl.bus.shm_ring import HEADER
from rosl.bus.transport import channel_of
from rosl.bus.wire import Writer
from tests.bus import shm_snippets as snippets
from tests.bus.helpers import Lines, wait_exit

if TYPE_CHECKING:
    from collections.abc import Iterator

    from rosl.bus.transport import Receiver
    from rosl.bus.wire import Delivery
    from tests.conftest import Processes

TOPIC = "/shm_ring"
SENDER, ENDPOINT = 0x5151, 7
RING_WRITER = r"""
import os, sys
from rosl.bus.multicast import Addressing, MulticastTransport
from rosl.bus.wire import Writer

domain, count, size = (int(a) for a in sys.argv[1:4])
transport = MulticastTransport(Addressing(domain))
writer = Writer(transport, 0x5151, 7, "/shm_ring", "test/msg/Bytes")
writer.use_shm(lambda: True)
for i in range(count):
    writer.send(i.to_bytes(4, "little") * (size // 4))
print("sent", writer.shm_sent, transport.shm.path(0x5151, 7, os.getpid(), 1), flush=True)
sys.stdin.readline()  # keep the ring until told
transport.close()
print("closed", flush=True)
"""


@pytest.fixture
def bus(domain_id: int) -> Iterator[tuple[MulticastTransport, Receiver]]:
    """A transport of the test's domain and a receiver listening to TOPIC (closed after)."""
    transport = MulticastTransport(Addressing(domain_id))
    receiver = transport.receiver()
    topic = topic_hash(TOPIC)
    receiver.reader.wanted.add(topic)
    receiver.join(channel_of(topic))
    try:
        yield transport, receiver
    finally:
        transport.close()


def shm_writer(transport: MulticastTransport) -> Writer:
    """A writer on TOPIC that sends large messages through shared memory."""
    writer = Writer(transport, SENDER, ENDPOINT, TOPIC, "test/msg/Bytes")
    writer.use_shm(lambda: True)
    return writer


def pattern(index: int, size: int) -> bytes:
    return index.to_bytes(4, "little") * (size // 4)


def ring_writer(
    processes: Processes, domain: int, count: int, size: int
) -> tuple[Lines, str, subprocess.Popen[str]]:
    """A child that sends ``count`` messages of ``size`` bytes through its ring, then waits."""
    child = processes.python(RING_WRITER, str(domain), str(count), str(size), stdin=subprocess.PIPE)
    out = Lines(child.stdout)
    line = out.wait_line("sent ", 30.0)
    assert line is not None, f"the ring writer never sent: {Lines(child.stderr).rest(2.0)}"
    _, sent, path = line.split()
    assert int(sent) == count
    return out, path, child


def talk(
    processes: Processes, count: int, listener_env: dict[str, str], prefix: tuple[str, ...] = ()
) -> tuple[subprocess.Popen[str], Lines, list[str]]:
    """A listener (its command after ``prefix``), then a talker of ``count`` rounds.

    Every round must arrive intact.

    Returns:
        The talker, its output, and its counts of descriptors sent (image, text, small).
    """
    command = [*prefix, sys.executable, "-c", snippets.LISTENER, "shm_listener"]
    listener = processes.start(command, env=listener_env)
    heard = Lines(listener.stdout)
    assert heard.wait_line("up", 30.0), Lines(listener.stderr).rest(2.0)
    talker = processes.python(snippets.TALKER, str(count), "1")
    said = Lines(talker.stdout)
    line = said.wait_line("shm ", 60.0)
    assert line is not None, Lines(talker.stderr).rest(2.0)
    assert heard.wait_for(lambda lines: snippets.complete(lines, count), 30.0), heard.lines
    assert not snippets.bads(heard.lines)
    return talker, said, line.split()[1:]


def test_large_messages_with_and_without_arrays_cross_through_shared_memory(
    processes: Processes, domain_id: int
) -> None:
    talker, said, shm = talk(processes, 10, {})
    # the image, the long and the mid-size string as descriptors, not the small one
    assert shm == ["10", "10", "10", "0"]

    rings = sorted(Path(DIRECTORY).glob(f"rosl-u{os.geteuid()}-d{domain_id}-p{talker.pid}-*"))
    assert len(rings) == 3, rings  # one per publisher that sent large messages
    for ring in rings:
        assert stat.S_IMODE(ring.stat().st_mode) == 0o600
    talker.send_signal(signal.SIGINT)  # a clean close unlinks them
    assert said.wait_line("closed", 30.0), Lines(talker.stderr).rest(2.0)
    assert wait_exit(talker, 15.0) == 0
    assert not [ring for ring in rings if ring.exists()]


def test_a_subscriber_without_shared_memory_gets_the_bytes(
    processes: Processes, domain_id: int
) -> None:
    _, _, shm = talk(processes, 5, {"ROSL_SHM": "0"})
    assert shm == ["0", "0", "0", "0"]  # the listener announced no shared memory: all on the wire


@pytest.mark.skipif(
    os.geteuid() != 0 or shutil.which("unshare") is None, reason="needs root and unshare"
)
def test_a_subscriber_with_its_own_dev_shm_gets_the_bytes(
    processes: Processes, domain_id: int
) -> None:
    # the same host, network and user, but a /dev/shm of its own (a container with the
    # host's network and its own IPC): it cannot see the talker's rings
    private = 'mount -t tmpfs -o size=16m tmpfs /dev/shm && exec "$@"'
    prefix = ("unshare", "--mount", "--propagation", "private", "sh", "-c", private, "sh")
    _, _, shm = talk(processes, 5, {}, prefix)
    assert shm == ["0", "0", "0", "0"]  # all on the wire


def test_a_slow_subscriber_never_reads_an_overwritten_slot(
    processes: Processes, domain_id: int, bus: tuple[MulticastTransport, Receiver]
) -> None:
    _, receiver = bus
    # the writer fills its ring more than twice before this process reads anything
    count, size = 160, 1_000_000
    out, path, child = ring_writer(processes, domain_id, count, size)
    got: list[Delivery] = []
    idle = 0
    while idle < 3:
        before = len(got)
        receiver.poll(0.3, got)
        idle = idle + 1 if len(got) == before else 0
    reader = receiver.reader
    overwritten = reader.dropped()["overwritten"]
    indices = [int.from_bytes(bytes(d.payload[:4]), "little") for d in got]
    for delivery, index in zip(got, indices, strict=True):
        assert bytes(delivery.payload) == pattern(index, size), f"message {index} is torn"
    assert got, "the newest ring of messages is still readable"
    with open(path, "rb") as ring:
        slots = HEADER.unpack(ring.read(HEADER.size))[1]  # 59 of 1 MB and an eighth: 64 MiB
    assert slots < count // 2
    assert overwritten >= count - slots
    assert len(got) + overwritten == count
    assert min(indices) >= overwritten  # only the newest survive
    # a reader nearly a ring behind copies nothing the writer is about to reuse: it drops a
    # sixteenth of the ring more and reads the rest, the newest
    assert indices == list(range(count - len(got), count))
    assert len(got) <= slots - slots // 16
    assert reader.lost() == overwritten  # counted where loss is reported
    assert child.stdin is not None
    child.stdin.write("\n")
    child.stdin.flush()
    assert out.wait_line("closed", 15.0)


def test_a_crashed_publisher_leaves_no_ring_behind_the_next_process(
    processes: Processes, domain_id: int
) -> None:
    _, crashed, victim = ring_writer(processes, domain_id, 1, 100_000)
    _, alive, _ = ring_writer(processes, domain_id, 1, 100_000)
    pid = victim.pid
    name = Path(crashed).name
    assert name.startswith(f"rosl-u{os.geteuid()}-d{domain_id}-p{pid}-"), name
    assert stat.S_IMODE(Path(crashed).stat().st_mode) == 0o600
    os.kill(pid, signal.SIGKILL)
    assert wait_exit(victim, 15.0) is not None
    assert Path(crashed).exists()  # nobody unlinked it: the process died
    sweeper = processes.python(
        "import sys\nfrom rosl.bus.multicast import Addressing, MulticastTransport\n"
        "t = MulticastTransport(Addressing(int(sys.argv[1])))\n"
        "print('swept', *t.shm.swept, flush=True)\nt.close()\n",
        str(domain_id),
    )
    line = Lines(sweeper.stdout).wait_line("swept", 30.0)
    assert line is not None, Lines(sweeper.stderr).rest(2.0)
    # any rosl process starting on this machine sweeps (a parallel test's may come first):
    # the ring is gone once a new process has started, whoever swept it
    assert name in line.split() or not Path(crashed).exists()
    assert not Path(crashed).exists()
    assert Path(alive).exists()  # a running publisher's ring is left alone


def test_a_ring_others_can_read_is_refused_and_counted(
    bus: tuple[MulticastTransport, Receiver],
) -> None:
    transport, receiver = bus
    writer = shm_writer(transport)
    writer.send(pattern(1, 100_000))
    assert transport.shm is not None
    ring = Path(transport.shm.path(SENDER, ENDPOINT, os.getpid(), 1))
    ring.chmod(0o644)
    got: list[Delivery] = []
    while receiver.poll(2.0, got) and not receiver.reader.dropped()["unmapped"]:
        pass
    assert not got
    assert receiver.reader.dropped()["unmapped"] == 1
    assert receiver.reader.lost() == 1
    ring.chmod(0o600)
    writer.send(pattern(2, 100_000))
    while not got and receiver.poll(2.0, got):
        pass
    assert [bytes(d.payload) for d in got] == [pattern(2, 100_000)]
    assert writer.shm_sent == 2
    transport.close()
    assert not ring.exists()  # the transport's close unlinked it


def test_shared_memory_can_be_turned_off(processes: Processes, domain_id: int) -> None:
    child = processes.python(
        "import sys\nfrom rosl.bus.multicast import Addressing, MulticastTransport\n"
        "print('shm', MulticastTransport(Addressing(int(sys.argv[1]))).shm, flush=True)\n",
        str(domain_id),
        env={"ROSL_SHM": "off"},
    )
    assert Lines(child.stdout).wait_line("shm", 30.0) == "shm None"


@pytest.mark.parametrize(
    ("name", "value", "words"),
    [
        ("ROSL_SHM", "maybe", "ROSL_SHM='maybe' is neither on"),
        ("ROSL_SHM_THRESHOLD", "12k", "ROSL_SHM_THRESHOLD='12k' is not a number of bytes"),
        ("ROSL_SHM_THRESHOLD", "0", "ROSL_SHM_THRESHOLD='0' is not a number of bytes"),
    ],
)
def test_a_bad_shared_memory_setting_is_one_line_naming_it(
    domain_id: int, name: str, value: str, words: str
) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "rosl", "topic", "list"],
        capture_output=True,
        text=True,
        timeout=60,
        env={**os.environ, name: value},
        check=False,
    )
    assert result.returncode == 1, result.stderr
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(words)


def test_a_descriptor_of_message_zero_is_refused(bus: tuple[MulticastTransport, Receiver]) -> None:
    # writers number their messages from 1; an unwritten slot's generation (0) equals what a
    # message 0 would expect, so a forged descriptor naming 0 must not read the zeros there
    from rosl.bus.shm_ring import DESCRIPTOR

    transport, _ = bus
    writer = shm_writer(transport)
    writer.send(pattern(1, 100_000))
    assert transport.shm is not None
    reader = transport.shm.reader()
    forged = DESCRIPTOR.pack(os.getpid(), 1, 0, 100_000)
    assert reader.read(SENDER, ENDPOINT, forged) is None
    assert reader.unmapped == 1
    real = DESCRIPTOR.pack(os.getpid(), 1, 1, 100_000)
    assert bytes(reader.read(SENDER, ENDPOINT, real) or b"") == pattern(1, 100_000)


FORKED_CHILD = r"""
import os, sys
from rosl.bus.multicast import Addressing, MulticastTransport
from rosl.bus.wire import Writer

transport = MulticastTransport(Addressing(int(sys.argv[1])))
writer = Writer(transport, 0x5151, 7, "/shm_ring", "test/msg/Bytes")
writer.use_shm(lambda: True)
writer.send(bytes(100_000))
path = transport.shm.path(0x5151, 7, os.getpid(), 1)
child = os.fork()
if child == 0:  # it writes a ring of its own, and leaves its parent's alone
    writer.send(bytes(100_000))
    mine = transport.shm.path(0x5151, 7, os.getpid(), 1)
    print("child", os.path.exists(mine), flush=True)
    transport.close()
    print("child closed", os.path.exists(mine), flush=True)
    sys.exit(0)  # the child's interpreter exits normally: finalizers and atexit run
os.waitpid(child, 0)
print("after fork", os.path.exists(path), flush=True)
writer.send(bytes(100_000))  # the parent's ring is still its own to write
print("parent", os.path.exists(path), transport.shm._failed, flush=True)
transport.close()
print("after close", os.path.exists(path), flush=True)
"""


def test_a_forked_child_leaves_its_parents_rings(processes: Processes, domain_id: int) -> None:
    child = processes.python(FORKED_CHILD, str(domain_id))
    out = Lines(child.stdout)
    assert out.wait_line("child ", 30.0) == "child True", Lines(child.stderr).rest(2.0)
    assert out.wait_line("child closed", 30.0) == "child closed False"
    assert out.wait_line("after fork", 30.0) == "after fork True", Lines(child.stderr).rest(2.0)
    assert out.wait_line("parent", 30.0) == "parent True False"
    assert out.wait_line("after close", 30.0) == "after close False"


@pytest.mark.parametrize(
    ("value", "machine", "expected"),
    [
        ("", "x86_64", True),
        ("", "aarch64", False),  # the ring's sequence check needs ordered stores
        ("", "armv7l", False),
        ("1", "aarch64", True),  # asked for knowingly
        ("off", "x86_64", False),
    ],
)
def test_shared_memory_is_on_by_default_only_where_stores_stay_in_order(
    value: str, machine: str, expected: bool
) -> None:
    from rosl.bus.shm import enabled

    assert enabled({"ROSL_SHM": value}, machine) is expected


def test_messages_above_16_kib_take_shared_memory_by_default(
    bus: tuple[MulticastTransport, Receiver],
) -> None:
    from rosl.bus.shm import threshold

    transport, receiver = bus
    assert threshold({}) == 16 * 1024
    assert transport.shm is not None
    limit = transport.shm.threshold  # the default, unless the environment sets another
    writer = shm_writer(transport)
    sizes = [limit, limit + 4, 60_000]  # at the threshold: the wire; above it: shared memory
    for index, size in enumerate(sizes):
        writer.send(pattern(index, size))
    # the 60 KB message outgrew the first ring, and the writer is closed before anything is
    # read: both rings stay (for a while) until the subscriber has mapped them
    writer.close()
    got: list[Delivery] = []
    while len(got) < len(sizes) and receiver.poll(5.0, got):
        pass
    assert [bytes(d.payload) for d in got] == [pattern(i, n) for i, n in enumerate(sizes)]
    assert writer.shm_sent == 2


def test_plain_sends_above_a_low_threshold_take_shared_memory(
    domain_id: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROSL_SHM_THRESHOLD", "1000")  # below where a plain send joins buffers
    transport = MulticastTransport(Addressing(domain_id))
    try:
        if transport.shm is None:
            pytest.skip("no shared memory on this machine")
        receiver = transport.receiver()
        topic = topic_hash(TOPIC)
        receiver.reader.wanted.add(topic)
        receiver.join(channel_of(topic))
        writer = shm_writer(transport)
        sizes = [10, 1000, 1004, 1500]
        for index, size in enumerate(sizes):
            writer.send_plain(pattern(index, size))
        got: list[Delivery] = []
        while len(got) < len(sizes) and receiver.poll(5.0, got):
            pass
        assert [bytes(d.payload) for d in got] == [pattern(i, n) for i, n in enumerate(sizes)]
        assert [d.seq for d in got] == [1, 2, 3, 4]
        assert writer.shm_sent == 2
        writer.close()
    finally:
        transport.close()


def test_a_ring_of_many_mid_size_slots_delivers_every_message_intact(
    bus: tuple[MulticastTransport, Receiver],
) -> None:
    # 20 KB messages: slots of 24 KiB (the size and an eighth, in pages), 1024 of them (their
    # generations take three pages of the ring's header); more messages than slots, read as
    # they come, all arrive intact
    from rosl.bus.shm_ring import segment_size

    transport, receiver = bus
    writer = shm_writer(transport)
    size, count, batch = 20_000, 1100, 100
    got: list[Delivery] = []
    for first in range(0, count, batch):
        for index in range(first, first + batch):
            writer.send(pattern(index, size))
        while len(got) < first + batch and receiver.poll(5.0, got):
            pass
    assert [bytes(d.payload) for d in got] == [pattern(i, size) for i in range(count)]
    assert writer.shm_sent == count
    assert transport.shm is not None
    ring = Path(transport.shm.path(SENDER, ENDPOINT, os.getpid(), 1))
    assert ring.stat().st_size == segment_size(1024, 24 * 1024)
    assert receiver.reader.lost() == 0


def test_a_reader_nearly_lapped_drops_a_sixteenth_of_the_ring_and_reads_on() -> None:
    # a ring of 64 slots: a reader the writer nearly laps (within 64 // 16 = 4 slots) copies
    # nothing the writer may reuse meanwhile: it drops 4 messages and reads the next
    from rosl.bus.shm import this_process
    from rosl.bus.shm_ring import RingReader, RingWriter

    path = os.path.join(DIRECTORY, f"rosl-test-lap-{os.getpid()}")
    writer = RingWriter(path, this_process(), 1, 64, 4096)
    try:
        reader = RingReader(lambda *_: path)
        sent = [writer.put(pattern(i, 4096)) for i in range(1, 65)]  # messages 1..64

        def read(number: int) -> bool:
            got = reader.read(SENDER, ENDPOINT, sent[number - 1])
            assert got is None or bytes(got) == pattern(number, 4096), number
            return got is not None

        assert not read(1)  # the writer has begun message 61
        assert [n for n in range(2, 6) if read(n)] == [5]  # 1..4 made room
        sent += [writer.put(pattern(i, 4096)) for i in range(65, 69)]  # ..68: 6 is near again
        assert [n for n in range(6, 69) if read(n)] == list(range(10, 69))
        assert reader.overwritten == 4 + 4
    finally:
        writer.close()
