"""Reliable readers hold a shared-memory writer back, briefly, instead of losing messages.

Real processes on the test's domain: a reader process takes the first message of a writer
in this process, then waits for the test's word before it reads on, while the writer (a
thread here) goes round its ring. A reliable reader keeps the writer waiting and gets every
message; a best-effort reader, or a best-effort writer, loses the oldest (counted, never
torn); a reader that stops reading, or is killed, holds the writer only briefly, and one
that keeps it waiting past its budget is not waited for.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import threading
import time
from array import array
from types import SimpleNamespace
from typing import TYPE_CHECKING

import pytest

from rosl.bus.multicast import Addressing, MulticastTransport
from rosl.bus.wire import Writer
from tests.bus.helpers import Lines, wait_exit
from tests.conftest import wait_until

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from rosl.bus.shm_ring import RingReader, RingWriter

    Small = tuple[RingWriter, Callable[[int], bytes]]
    from tests.conftest import Processes

TOPIC = "/shm_hold"
SENDER, ENDPOINT = 0x5152, 3
COUNT, SIZE = 120, 1_000_000  # slots of 1 MB and an eighth: 59 in a ring of 64 MiB
LONG_NS = 60_000_000_000  # a hold no loaded machine outlasts (the writer waits for the test)

READER = r"""
import sys
from rosl.bus.header import topic_hash
from rosl.bus.multicast import Addressing, MulticastTransport
from rosl.bus.transport import channel_of

domain, count, size, hold = (int(a) for a in sys.argv[1:5])
transport = MulticastTransport(Addressing(domain))
receiver = transport.receiver()
topic = topic_hash("/shm_hold")
receiver.reader.wanted.add(topic)
if hold:
    receiver.reader.held.add(topic)  # a reliable subscription takes the topic
receiver.join(channel_of(topic))
print("ready", flush=True)
out, got, torn = [], 0, 0
def take():
    global got, torn
    for d in out:
        index = int.from_bytes(bytes(d.payload[:4]), "little")
        torn += bytes(d.payload) != index.to_bytes(4, "little") * (size // 4)
        got += 1
    out.clear()
while not out:
    receiver.poll(0.5, out)
take()
print("first", flush=True)
if sys.stdin.readline().strip() == "stop":
    sys.stdin.readline()  # reads nothing more, and holds its entry, until told to leave
else:
    idle = 0
    while got + receiver.reader.lost() < count and idle < 20:
        receiver.poll(0.25, out)
        idle = 0 if out else idle + 1
        take()
print("got", got, "lost", receiver.reader.lost(), "torn", torn, flush=True)
transport.close()
"""


def pattern(index: int, size: int) -> bytes:
    return index.to_bytes(4, "little") * (size // 4)


class Burst:
    """A writer in this process, its first message sent; ``go`` sends the rest on a thread."""

    def __init__(self, domain: int, hold: bool) -> None:
        self.transport = MulticastTransport(Addressing(domain))
        self.writer = Writer(self.transport, SENDER, ENDPOINT, TOPIC, "test/msg/Bytes")
        self.writer.use_shm(lambda: True)
        self.writer.shm_hold = hold
        self.thread = threading.Thread(target=self._rest, daemon=True)

    def first(self) -> RingWriter:
        self.writer.send(pattern(0, SIZE))
        assert self.transport.shm is not None
        return self.transport.shm._rings[(SENDER, ENDPOINT)]

    def _rest(self) -> None:
        for index in range(1, COUNT):
            self.writer.send(pattern(index, SIZE))

    def go(self) -> None:
        self.thread.start()

    def done(self, timeout: float) -> bool:
        self.thread.join(timeout)
        return not self.thread.is_alive()

    def close(self) -> None:
        self.transport.close()


def reader(processes: Processes, domain: int, hold: bool) -> tuple[subprocess.Popen[str], Lines]:
    child = processes.python(
        READER, str(domain), str(COUNT), str(SIZE), str(int(hold)), stdin=subprocess.PIPE
    )
    out = Lines(child.stdout)
    assert out.wait_line("ready", 30.0), Lines(child.stderr).rest(2.0)
    return child, out


def tell(child: subprocess.Popen[str], word: str) -> None:
    assert child.stdin is not None
    child.stdin.write(word + "\n")
    child.stdin.flush()


def counts(out: Lines) -> tuple[int, int, int]:
    line = out.wait_line("got ", 60.0)
    assert line is not None
    _, got, _, lost, _, torn = line.split()
    return int(got), int(lost), int(torn)


def first_heard(burst: Burst, child: subprocess.Popen[str], out: Lines) -> RingWriter:
    ring = burst.first()
    assert out.wait_line("first", 30.0), Lines(child.stderr).rest(2.0)
    return ring


@pytest.mark.parametrize(
    ("reader_holds", "writer_holds"),
    [(True, True), (False, True), (True, False)],
    ids=["reliable", "best_effort_reader", "best_effort_writer"],
)
def test_a_reliable_reader_behind_by_more_than_a_ring_keeps_a_reliable_writer_waiting(
    processes: Processes, domain_id: int, reader_holds: bool, writer_holds: bool
) -> None:
    # the reader holds at message 0 while the writer goes round its ring of 59 slots: a
    # reliable reader keeps a reliable writer waiting (it waits for the test here, which
    # says "go" only then) and gets all 120 messages; a best-effort reader is not waited
    # for, a best-effort writer waits for nobody, and the reader loses the oldest, counted
    reliable = reader_holds and writer_holds
    child, out = reader(processes, domain_id, hold=reader_holds)
    burst = Burst(domain_id, hold=writer_holds)
    try:
        ring = first_heard(burst, child, out)
        ring.hold_ns = ring.max_wait_ns = ring.budget_ns = LONG_NS
        burst.go()
        if reliable:
            assert wait_until(lambda: ring.waited > 0, 30.0), "the writer never waited"
            assert not burst.done(0.0), "the writer went round its reader"
        else:
            assert burst.done(60.0)
        tell(child, "go")
        got, lost, torn = counts(out)
        assert burst.done(60.0)
        assert torn == 0
        if reliable:
            assert (got, lost) == (COUNT, 0)
            assert ring.waited_out == 0
        else:
            assert ring.waited == 0
            assert lost >= COUNT - ring.slots
            assert got + lost == COUNT
        assert wait_exit(child, 30.0) == 0
        assert ring._holders() == []  # the reader gave its entry back as it left
    finally:
        burst.close()


def test_a_reader_that_keeps_the_writer_waiting_past_its_budget_is_not_waited_for(
    processes: Processes, domain_id: int
) -> None:
    # a reliable reader that reads no more (but read recently, as far as the writer can
    # tell: a long hold) is steadily slower than its writer, not behind by a burst: once it
    # cost the writer its budget (25 ms of waits within 100 ms), the writer goes on without
    # it, and the reader loses the oldest, counted
    child, out = reader(processes, domain_id, hold=True)
    burst = Burst(domain_id, hold=True)
    try:
        ring = first_heard(burst, child, out)
        ring.hold_ns = ring.max_wait_ns = LONG_NS
        burst.go()
        assert burst.done(60.0), "the writer kept waiting past the reader's budget"
        assert ring.waited >= 1
        assert ring.excused == 1
        assert ring.waited_out == 0
        tell(child, "go")
        got, lost, torn = counts(out)
        assert (torn, got + lost) == (0, COUNT)
        assert lost >= COUNT - ring.slots
        assert wait_exit(child, 30.0) == 0
    finally:
        burst.close()


def _stop(child: subprocess.Popen[str]) -> None:
    tell(child, "stop")


def _kill(child: subprocess.Popen[str]) -> None:
    child.send_signal(signal.SIGKILL)
    child.wait(30.0)


@pytest.mark.parametrize("leave", [_stop, _kill], ids=["stops_reading", "killed"])
def test_a_reader_that_stops_reading_holds_the_writer_at_most_once(
    processes: Processes, domain_id: int, leave: Callable[[subprocess.Popen[str]], None]
) -> None:
    # with the usual hold (a reader that read nothing for 10 ms is not waited for), a reader
    # that takes message 0 and then reads no more, alive or killed, costs the writer one
    # wait at most (if the writer reached it within those 10 ms), never a wait run out
    child, out = reader(processes, domain_id, hold=True)
    burst = Burst(domain_id, hold=True)
    try:
        ring = first_heard(burst, child, out)
        leave(child)
        burst.go()
        assert burst.done(60.0), "the writer kept waiting for a reader that reads no more"
        assert ring.waited <= 1
        assert ring.waited_out == 0
        assert ring._holders(), "the reader's entry is still taken (it never gave it back)"
    finally:
        burst.close()
        if child.poll() is None:
            tell(child, "leave")
            assert wait_exit(child, 30.0) == 0


# --- one ring in this process: the readers' page itself -----------------------------------


@pytest.fixture
def ring_path(request: pytest.FixtureRequest) -> Iterator[str]:
    from rosl.bus.shm import DIRECTORY

    path = os.path.join(DIRECTORY, f"rosl-test-hold-{os.getpid()}-{request.node.name[:40]}")
    yield path
    with contextlib.suppress(OSError):
        os.unlink(path)


@pytest.fixture
def small(ring_path: str) -> Iterator[Small]:
    """A ring of 16 slots of 4 KiB, and a function writing message ``n`` into it."""
    from rosl.bus.shm import this_process
    from rosl.bus.shm_ring import RingWriter

    writer = RingWriter(ring_path, this_process(), 1, 16, 4096)

    def put(number: int) -> bytes:
        writer.make_room()
        return writer.put(pattern(number, 4096))

    yield writer, put
    writer.close()


def reader_of(path: str) -> RingReader:
    from rosl.bus.shm_ring import RingReader

    return RingReader(lambda *_: path)


def holding_first(path: str, put: Callable[[int], bytes]) -> tuple[RingReader, list[bytes]]:
    """A reader of the ring at ``path`` that took message 1 as a reliable reader does."""
    reader = reader_of(path)
    sent = [put(1)]
    assert reader.read(SENDER, ENDPOINT, sent[0], hold=True) is not None
    return reader, sent


def test_an_excused_reader_is_waited_for_again_once_it_caught_up(
    ring_path: str, small: Small
) -> None:
    writer, put = small
    reader, sent = holding_first(ring_path, put)
    writer.hold_ns, writer.budget_ns = LONG_NS, 0  # any wait spends the budget
    sent += [put(n) for n in range(2, 18)]  # 17 would push the reader into dropping
    assert (writer.waited, writer.excused, writer.waited_out) == (1, 1, 0)
    got = [reader.read(SENDER, ENDPOINT, d, hold=True) for d in sent[1:]]
    assert sum(g is not None for g in got) == 15  # 2 was dropped to make room
    sent.append(put(18))  # caught up: no longer excused
    assert writer._excused == set()
    writer.budget_ns, writer.max_wait_ns = LONG_NS, 1_000_000
    for number in range(19, 34):  # 33 pushes it again: waited for (1 ms), not excused
        sent.append(put(number))
    assert (writer.excused, writer.waited_out) == (1, 1)


def test_an_entry_whose_reader_read_nothing_for_10_s_goes_to_the_next_reader(
    ring_path: str, small: Small
) -> None:
    from rosl.bus.shm_ring import CLAIM_STALE_NS

    writer, put = small
    first, second = (reader_of(ring_path) for _ in range(2))
    descriptor = put(1)
    assert first.read(SENDER, ENDPOINT, descriptor, hold=True) is not None
    (mapped,) = first._maps.values()
    assert mapped.entries is not None
    taken = mapped.entry
    mapped.entries[taken + 2] = time.monotonic_ns() - CLAIM_STALE_NS - 1  # long idle
    assert second.read(SENDER, ENDPOINT, descriptor, hold=True) is not None
    (other,) = second._maps.values()
    assert other.entry == taken  # the idle reader's entry, not a free one
    assert first.read(SENDER, ENDPOINT, put(2), hold=True) is not None
    assert mapped.entry not in (-1, taken)  # it took another when it read again
    assert sorted(writer._holders()) == sorted([taken, mapped.entry])


def test_a_forked_child_leaves_its_parents_entry_alone(ring_path: str, small: Small) -> None:
    writer, put = small
    reader = reader_of(ring_path)
    assert reader.read(SENDER, ENDPOINT, put(1), hold=True) is not None
    holders = writer._holders()
    assert len(holders) == 1
    (mapped,) = reader._maps.values()
    assert mapped.entries is not None
    before = list(mapped.entries[holders[0] : holders[0] + 3])  # token, cursor, stamp
    pid = os.fork()
    if pid == 0:  # the child: reads (an entry of its own), gives back what it holds, goes
        code = 1
        try:
            reader.read(SENDER, ENDPOINT, put(2), hold=True)
            code = 0 if mapped.entry not in (-1, holders[0]) else 2
            reader.release()
        finally:
            os._exit(code)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0
    assert writer._holders() == holders
    assert list(mapped.entries[holders[0] : holders[0] + 3]) == before


def test_a_reader_finding_no_free_entry_looks_again_only_after_a_change(
    ring_path: str, small: Small, monkeypatch: pytest.MonkeyPatch
) -> None:
    import mmap

    from rosl.bus import shm_ring
    from rosl.bus.shm_ring import ENTRIES, FIRST_ENTRY, PAGE, readers_at

    # (however slow the machine: no look again for time alone, no entry idle long enough)
    monkeypatch.setattr(shm_ring, "CLAIM_RETRY_NS", LONG_NS)
    monkeypatch.setattr(shm_ring, "CLAIM_STALE_NS", LONG_NS)

    _, put = small
    with (
        open(ring_path, "r+b") as handle,
        mmap.mmap(handle.fileno(), PAGE, offset=readers_at(16)) as page,
        memoryview(page).cast("Q") as entries,
    ):
        now = time.monotonic_ns()
        for index in range(FIRST_ENTRY, 4 * ENTRIES, 4):  # every entry taken, all reading
            entries[index : index + 4] = array("Q", [index, 0, now, 1])
        reader = reader_of(ring_path)
        assert reader.read(SENDER, ENDPOINT, put(1), hold=True) is not None  # read, unheld
        (mapped,) = reader._maps.values()
        assert mapped.entry == -1
        entries[FIRST_ENTRY] = 0  # one is free, but the page's count of changes says nothing
        assert reader.read(SENDER, ENDPOINT, put(2), hold=True) is not None
        assert mapped.entry == -1  # not looked at again
        entries[0] += 1  # (as a reader leaving counts it)
        assert reader.read(SENDER, ENDPOINT, put(3), hold=True) is not None
        assert mapped.entry == FIRST_ENTRY


@pytest.mark.parametrize("budget_ns", [LONG_NS, 10_000], ids=["credit", "overdrawn"])
def test_every_pause_of_a_wait_is_charged_to_the_reader_it_waited_for(
    ring_path: str, small: Small, monkeypatch: pytest.MonkeyPatch, budget_ns: int
) -> None:
    # the reader catches up during the writer's first pause (50 us at least): that pause,
    # the last of the wait, counts against the reader's credit too; a reader it overdraws
    # is still not excused, since it caught up and lost nothing
    from rosl.bus import shm_ring

    writer, put = small
    reader, sent = holding_first(ring_path, put)
    writer.hold_ns = writer.max_wait_ns = LONG_NS
    writer.budget_ns = budget_ns
    sent += [put(n) for n in range(2, 17)]  # the next would push the reader into dropping

    def pause(seconds: float) -> None:  # the writer's sleep: the reader reads on meanwhile
        for descriptor in sent[1:]:
            reader.read(SENDER, ENDPOINT, descriptor, hold=True)
        time.sleep(seconds)

    monkeypatch.setattr(
        shm_ring, "time", SimpleNamespace(monotonic_ns=time.monotonic_ns, sleep=pause)
    )
    put(17)
    assert (writer.waited, writer.waited_out, writer.excused) == (1, 0, 0)
    assert writer.waited_ns >= 50_000
    ((credit, _),) = writer._credit.values()
    assert credit <= writer.budget_ns - 50_000


def test_a_reader_taking_an_entry_over_starts_with_a_clean_slate(
    ring_path: str, small: Small
) -> None:
    # a reader excused (its credit spent) leaves; the next reader in its entry is waited for

    writer, put = small
    first, sent = holding_first(ring_path, put)
    writer.hold_ns, writer.budget_ns = LONG_NS, 0
    sent += [put(n) for n in range(2, 18)]
    assert writer.excused == 1
    (taken,) = writer._excused
    first.release()
    second = reader_of(ring_path)
    assert second.read(SENDER, ENDPOINT, sent[-1], hold=True) is not None  # number 17
    (mapped,) = second._maps.values()
    assert mapped.entry == taken
    assert taken in writer._credit  # (spent: below nothing)
    writer.make_room()  # sees the page changed
    assert taken not in writer._credit
    assert taken not in writer._excused
    writer.budget_ns, writer.max_wait_ns = LONG_NS, 1_000_000
    for number in range(18, 34):  # 33 would push the new reader into dropping
        put(number)
    assert (writer.excused, writer.waited_out) == (1, 1)  # waited for, not excused
