"""Floods against one node: its memory, and the valid traffic it still gets, while strangers and
key holders blast its domain.

Two node processes on their own domain: a talker publishing std_msgs/msg/String ``hello N`` on
/bench_flood at --talker-hz, and a victim subscribed to it (queue depth --depth) that prints its
counts every 0.2 s. The victim tells apart the talker's messages, messages of key holders
(``keyed N``: any process holding the key may publish, by design) and everything else (forged:
must never be delivered), and counts deliveries it got twice (a talker (publisher gid, sequence
number) or a ``keyed N`` seen before: must stay 0). This process measures the valid msg/s
without a flood (the baseline), then floods from 127.0.0.1 with TTL 0, for --seconds per mode,
at about --rate datagrams/s (sent in 10 ms batches; fragments of 60 KB and less at a quarter):

  strangers      another user's traffic: signed under another key, unsigned, or with a wrong
                 MAC; data (single and fragments) on the topic's channel, discovery on channel 0
  fragments      key holder: fragment 0 of messages that never complete, random sender ids,
                 claimed totals of 200 KB and 8 MB, fragments of 60 KB, 1 KB and 123 B
  fragments-tiny as fragments, all 8 MB claims in 123 B fragments (the smallest such)
  senders        key holder: single data messages from random sender ids on the topic
  replays        the talker's real datagrams, captured from the wire, resent over and over
  jumps          key holder: the talker's sender id and endpoint, sequence numbers far ahead
  jumps-near     as jumps, but only half a loss window ahead (a gap the bus counts as loss)
  jumps-future   as jumps, stamped an hour and 25 s ahead in turn (10 datagrams/s; last by
                 default: an accepted one can hold the talker's stream back that long)

Per mode: datagrams sent and offered/s; the victim's RSS (VmRSS of its pid) when the flood
starts, its peak over the flood and the --settle seconds after (VmHWM, reset per mode), and
at the end of those seconds; the talker's peak RSS growth; the victim's valid msg/s during the
flood and its ratio to the baseline; duplicates, forged and key-holder messages delivered to
its callback. A second table: what the victim's reader dropped during the mode (by reason),
its stream table, and the loss it counted against the real gaps its callback saw.

    python bench/flood.py [--seconds 10] [--settle 10] [--rate 20000] [--talker-hz 500]
                          [--depth 10] [--modes strangers fragments ...]
"""

from __future__ import annotations

import argparse
import contextlib
import random
import select
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from _harness import BENCH_DOMAIN, lock_domain, raw_sender
from _procs import bench_env, stop

if TYPE_CHECKING:
    from collections.abc import Callable

DOMAIN = BENCH_DOMAIN + 5
TOPIC = "/bench_flood"
TYPE = "std_msgs/msg/String"
PREFIX = "hello "
MODES = ["strangers", "fragments", "fragments-tiny", "senders", "replays", "jumps", "jumps-near",
         "jumps-future"]  # fmt: skip
MIB = 1024 * 1024
# (claimed total, fragment size) of the fragments mode, in turn; 123 B is the smallest fragment
# of an 8 MB message (the count field has 16 bits)
FRAGMENTS = [(8_000_000, 60_000), (200_000, 60_000), (8_000_000, 123), (200_000, 1000)]


# --- the two node processes ---------------------------------------------------------------------


def talker(rate: float) -> None:
    import rosl
    from rosl.idl.registry import get_message_class

    String = get_message_class(TYPE)  # noqa: N806
    rosl.init([], domain_id=DOMAIN)
    node = rosl.Node("flood_talker")
    pub = node.create_publisher(String, TOPIC, 10)
    count = 0

    def tick() -> None:
        nonlocal count
        count += 1
        pub.publish(String(data=f"{PREFIX}{count}"))

    node.create_timer(1.0 / rate, tick)
    print("ready", flush=True)
    with contextlib.suppress(KeyboardInterrupt):
        rosl.spin(node)
    rosl.shutdown()


def victim(depth: int) -> None:
    import rosl
    from rosl.bus.header import topic_hash
    from rosl.idl.registry import get_message_class

    String = get_message_class(TYPE)  # noqa: N806
    rosl.init([], domain_id=DOMAIN)
    node = rosl.Node("flood_victim")
    reader = node.participant.reader
    topic = topic_hash(TOPIC)
    seen = bytearray(1 << 17)  # talker sequence numbers delivered (a bit each)
    keyed_seen = bytearray(1 << 21)  # "keyed N" numbers delivered (a bit each)
    c = {"good": 0, "keyed": 0, "forged": 0, "dup": 0, "kdup": 0}
    talker_gid: Any = None
    first = last = 0

    def mark(bits: bytearray, number: int) -> bool:
        """Set bit ``number``; return whether it was set before."""
        while number >> 3 >= len(bits):
            bits.extend(bytes(len(bits)))
        byte, bit = number >> 3, 1 << (number & 7)
        was = bits[byte] & bit
        bits[byte] |= bit
        return bool(was)

    def on_message(msg: Any, info: dict[str, Any]) -> None:
        nonlocal talker_gid, first, last
        data, gid = msg.data, info["publisher_gid"]
        seq = info["publication_sequence_number"]
        if data.startswith(PREFIX):
            if talker_gid is None:
                talker_gid, first = gid, seq
            if gid != talker_gid:
                c["forged"] += 1
            elif mark(seen, seq):
                c["dup"] += 1
            else:
                c["good"] += 1
                last = max(last, seq)
        elif data.startswith("keyed ") and data[6:].isdigit():
            c["kdup" if mark(keyed_seen, int(data[6:])) else "keyed"] += 1
        else:
            c["forged"] += 1

    sub = node.create_subscription(String, TOPIC, on_message, depth)

    def report() -> None:
        gaps = last - first + 1 - c["good"] if c["good"] else 0
        rs = node.participant.reader.reassembler
        fields = {
            "t": f"{time.monotonic():.3f}", **c, "gaps": gaps, "lost": reader.lost(topic),
            "streams": len(reader.streams), "retired": len(reader._retired),
            "held": rs.held, "pending": rs.pending, "oversize": rs.oversize,
            "subdropped": sub.dropped, "undecodable": sub.undecodable,
            **{f"drop_{k}": v for k, v in reader.dropped().items()},
        }  # fmt: skip
        print("stat", " ".join(f"{k}={v}" for k, v in fields.items()), flush=True)

    node.create_timer(0.2, report)
    print("ready", flush=True)
    with contextlib.suppress(KeyboardInterrupt):
        rosl.spin(node)
    rosl.shutdown()


# --- this process: watching the children ----------------------------------------------------------


def memory(pid: int) -> dict[str, int]:
    """VmRSS and VmHWM of ``pid`` in bytes (empty when it is gone)."""
    found: dict[str, int] = {}
    with contextlib.suppress(OSError), open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(("VmRSS:", "VmHWM:")):
                found[line[:5]] = int(line.split()[1]) * 1024
    return found


def reset_peak(pid: int) -> None:
    """Make VmHWM the current RSS (so it shows this mode's peak)."""
    with contextlib.suppress(OSError), open(f"/proc/{pid}/clear_refs", "w") as f:
        f.write("5")


class Child:
    """A node process of this bench: its pid, its latest ``stat`` line, its stderr in a file."""

    def __init__(self, name: str, args: list[str], folder: Path) -> None:
        self.name = name
        self.err_path = folder / f"{name}.err"
        self._err: IO[str] = self.err_path.open("w")
        self.proc = subprocess.Popen(
            [sys.executable, __file__, *args],
            stdout=subprocess.PIPE,
            stderr=self._err,
            text=True,
            env=bench_env(DOMAIN),
        )
        self.stats: dict[str, float] = {}
        self._ready = threading.Event()
        self._changed = threading.Condition()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            if line.startswith("stat "):
                fields = dict(x.split("=", 1) for x in line.split()[1:])
                with self._changed:
                    self.stats = {k: float(v) for k, v in fields.items()}
                    self._changed.notify_all()
            elif line.strip() == "ready":
                self._ready.set()

    def wait_ready(self, timeout: float = 30.0) -> None:
        if not self._ready.wait(timeout):
            raise RuntimeError(f"{self.name} did not start: {self.stderr()[-800:]}")

    def stat_after(self, moment: float, timeout: float = 30.0) -> dict[str, float]:
        """The first stat line printed at or after ``moment`` (time.monotonic; bounded wait)."""
        deadline = time.monotonic() + timeout
        with self._changed:
            while self.stats.get("t", -1.0) < moment:
                left = deadline - time.monotonic()
                if left <= 0 or self.proc.poll() is not None:
                    raise RuntimeError(f"{self.name} stopped reporting: {self.stderr()[-800:]}")
                self._changed.wait(min(left, 0.5))
            return dict(self.stats)

    def stderr(self) -> str:
        if not self._err.closed:
            self._err.flush()
        return self.err_path.read_text(errors="replace")

    def close(self) -> None:
        stop(self.proc, signal.SIGINT)
        self._err.close()


class Sampler:
    """Samples the RSS of some pids every 20 ms on a thread, keeping the peak of each."""

    def __init__(self, pids: list[int]) -> None:
        self.peak = {pid: 0 for pid in pids}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.02):
            for pid in self.peak:
                self.peak[pid] = max(self.peak[pid], memory(pid).get("VmRSS", 0))

    def finish(self) -> dict[int, int]:
        self._stop.set()
        self._thread.join(5.0)
        for pid in self.peak:  # VmHWM catches a peak between two samples
            self.peak[pid] = max(self.peak[pid], memory(pid).get("VmHWM", 0))
        return self.peak


# --- what the flood sends ----------------------------------------------------------------------


class Forge:
    """Builds the datagrams of every mode (as rosl's wire would, or as a stranger would)."""

    def __init__(self, domain: int, seed: int = 12) -> None:
        from rosl.bus import auth
        from rosl.bus.header import topic_hash, type_hash
        from rosl.bus.transport import channel_of
        from rosl.graph.announce import DISCOVERY_TOPIC, DISCOVERY_TYPE

        key = auth.load(domain)
        if key is None:
            raise SystemExit("flood.py needs the bus key (ROSL_KEY=none turns it off)")
        self.key = key
        self.other = auth.Auth(b"another user's key", domain, "bench")
        self.topic, self.type = topic_hash(TOPIC), type_hash(TYPE)
        self.channel = channel_of(self.topic)
        self.disc_topic, self.disc_type = topic_hash(DISCOVERY_TOPIC), type_hash(DISCOVERY_TYPE)
        self.rng = random.Random(seed)
        self.pool = self.rng.randbytes(60_000)
        self.keyed = 0
        self.talker: tuple[int, int] = (0, 0)  # (sender, endpoint), learned by capture()
        self.captured: list[bytes] = []
        self.talker_seq = 0  # the talker's newest sequence number seen, and when
        self.seen_at = 0.0
        self.talker_hz = 500.0

    def datagram(
        self,
        payload: bytes,
        sender: int,
        seq: int,
        *,
        sign: str = "key",
        kind: int = 1,
        endpoint: int = 1,
        count: int = 1,
        total: int | None = None,
        topic: tuple[int, int] | None = None,
        stamp: int | None = None,
    ) -> bytes:
        """One datagram; ``sign``: key (ours), other (another key), bad (wrong MAC), none."""
        from rosl.bus.header import HEADER, MAGIC, VERSION, Flags

        topic_hash, type_hash = topic or (self.topic, self.type)
        flags = 0 if sign == "none" else int(Flags.SIGNED)
        head = HEADER.pack(
            MAGIC, VERSION, kind, flags, count, sender, seq & 0xFFFFFFFF, topic_hash, type_hash,
            0, endpoint, len(payload) if total is None else total,
            time.time_ns() if stamp is None else stamp,
        )  # fmt: skip
        body = head + payload
        if sign == "key":
            return body + self.key.mac(body)
        if sign == "other":
            return body + self.other.mac(body)
        if sign == "bad":
            return body + self.rng.randbytes(16)
        return body

    def keyed_text(self) -> bytes:
        self.keyed += 1
        return cdr_string(f"keyed {self.keyed}")

    def strangers(self, n: int) -> tuple[int, bytes]:
        rng = self.rng
        sender, seq = rng.getrandbits(64), rng.getrandbits(32)
        sign = ("other", "none", "bad")[n % 3]
        variant = n % 5
        if variant == 4:  # a discovery hello of a made-up node
            hello = f'{{"op":"hello","process":{{"sender":"{sender:016x}","pid":{n},'
            hello += '"nodes":[{"name":"ghost","namespace":"/"}]}}'
            disc = (self.disc_topic, self.disc_type)
            return 0, self.datagram(hello.encode(), sender, seq, sign=sign, kind=4, topic=disc)
        if variant == 3:  # fragment 0 of an 8 MB message
            return self.channel, self.datagram(
                self.pool[:1000], sender, seq, sign=sign, count=8000, total=8_000_000
            )
        payload = cdr_string(f"stranger {n}")
        return self.channel, self.datagram(payload, sender, seq, sign=sign)

    def fragments(self, n: int) -> tuple[int, bytes]:
        total, size = FRAGMENTS[n % len(FRAGMENTS)]
        count = -(-total // size)
        sender = self.rng.getrandbits(64)
        datagram = self.datagram(self.pool[:size], sender, 1, count=count, total=total)
        return self.channel, datagram

    def fragments_tiny(self, n: int) -> tuple[int, bytes]:
        total, size = 8_000_000, 123  # the smallest fragment an 8 MB message can have
        sender = self.rng.getrandbits(64)
        datagram = self.datagram(self.pool[:size], sender, 1, count=65041, total=total)
        return self.channel, datagram

    def senders(self, n: int) -> tuple[int, bytes]:
        rng = self.rng
        sender, seq, endpoint = rng.getrandbits(64), rng.getrandbits(32), rng.randrange(1, 9)
        return self.channel, self.datagram(self.keyed_text(), sender, seq, endpoint=endpoint)

    def replays(self, n: int) -> tuple[int, bytes]:
        return self.channel, self.captured[n % len(self.captured)]

    def jumps(self, n: int) -> tuple[int, bytes]:
        # far ahead of the talker and of each other: 2**31 + multiples of 65537 (a prime) modulo
        # 2**31 - 2**20, so no two are within a loss window or near the talker's numbers
        seq = (1 << 31) + n * 65537 % ((1 << 31) - (1 << 20))
        sender, endpoint = self.talker
        return self.channel, self.datagram(self.keyed_text(), sender, seq, endpoint=endpoint)

    def jumps_near(self, n: int) -> tuple[int, bytes]:
        guess = self.talker_seq + int((time.monotonic() - self.seen_at) * self.talker_hz)
        seq = guess + 32768 + n  # half a loss window ahead: every one looks like a gap
        sender, endpoint = self.talker
        return self.channel, self.datagram(self.keyed_text(), sender, seq, endpoint=endpoint)

    def jumps_future(self, n: int) -> tuple[int, bytes]:
        seq = (1 << 31) + n * 65537
        stamp = time.time_ns() + (3600 if n % 2 else 25) * 10**9
        sender, endpoint = self.talker
        datagram = self.datagram(self.keyed_text(), sender, seq, endpoint=endpoint, stamp=stamp)
        return self.channel, datagram

    def capture(self, seconds: float = 2.0, want: int = 400) -> None:
        """Read the talker's real datagrams from the wire (for replays, and its id and seq)."""
        from rosl.bus.header import unpack
        from rosl.bus.multicast import Addressing, open_receiver

        sock = open_receiver(Addressing(DOMAIN), self.channel)
        got: list[bytes] = []
        deadline = time.monotonic() + seconds
        try:
            while time.monotonic() < deadline and len(got) < want:
                ready, _, _ = select.select([sock], [], [], 0.1)
                while ready:
                    try:
                        datagram = sock.recv(65536)
                    except BlockingIOError:
                        break
                    head = unpack(datagram)
                    if head is None or head.topic != self.topic or PREFIX.encode() not in datagram:
                        continue
                    got.append(datagram)
                    self.talker = (head.sender, head.endpoint)
                    self.talker_seq, self.seen_at = head.seq, time.monotonic()
        finally:
            sock.close()
        if not got:
            raise RuntimeError("captured none of the talker's datagrams")
        self.captured = got


def cdr_string(text: str) -> bytes:
    """A std_msgs/msg/String in CDR (little endian, with its encapsulation header)."""
    raw = text.encode() + b"\x00"
    return b"\x00\x01\x00\x00" + struct.pack("<I", len(raw)) + raw


def flood(make: Callable[[int], tuple[int, bytes]], rate: float, seconds: float) -> int:
    """Send ``make(n)`` datagrams at about ``rate``/s for ``seconds``; return how many went."""
    from rosl.bus.multicast import Addressing

    addressing = Addressing(DOMAIN)
    sock = raw_sender()
    batch = max(1, int(rate / 100))  # 10 ms worth, then a pause until they are due
    start = time.monotonic()
    sent = n = 0
    try:
        while True:
            now = time.monotonic()
            if now - start >= seconds:
                break
            due = start + n / rate
            if now < due:
                time.sleep(min(due - now, 0.01))
                continue
            for _ in range(batch):
                channel, datagram = make(n)
                n += 1
                with contextlib.suppress(OSError):  # a full send buffer: not sent
                    sock.sendto(datagram, (addressing.group(channel), addressing.port))
                    sent += 1
    finally:
        sock.close()
    return sent


# --- the run ---------------------------------------------------------------------------------


def mb(value: float) -> str:
    return f"{value / MIB:.1f}"


def run_mode(
    mode: str, forge: Forge, victim_: Child, talker_: Child, args: argparse.Namespace
) -> tuple[list[str], list[str], dict[str, float]]:
    vpid, tpid = victim_.proc.pid, talker_.proc.pid
    rate = args.rate / 4 if mode == "fragments" else args.rate
    if mode == "jumps-future":
        rate = 10.0  # a few are enough
    if mode in ("replays", "jumps", "jumps-near", "jumps-future"):
        forge.capture()
    make = getattr(forge, mode.replace("-", "_"))
    for pid in (vpid, tpid):
        reset_peak(pid)
    rss0, trss0 = memory(vpid).get("VmRSS", 0), memory(tpid).get("VmRSS", 0)
    before = victim_.stat_after(time.monotonic())
    sampler = Sampler([vpid, tpid])
    started = time.monotonic()
    sent = flood(make, rate, args.seconds)
    ended = time.monotonic()
    during = victim_.stat_after(ended)
    time.sleep(args.settle)
    after = victim_.stat_after(time.monotonic())
    rss_after = memory(vpid).get("VmRSS", 0)
    peak = sampler.finish()
    elapsed = during["t"] - before["t"]
    valid = (during["good"] - before["good"]) / elapsed if elapsed > 0 else 0.0

    def delta(key: str) -> int:
        return int(after[key] - before[key])

    offered = sent / (ended - started)
    row = [
        mode, str(sent), f"{offered:.0f}", mb(rss0), mb(peak[vpid]), mb(rss_after),
        mb(peak[tpid] - trss0), f"{valid:.0f}", "", str(delta("dup") + delta("kdup")),
        str(delta("forged")), str(delta("keyed")),
    ]  # fmt: skip
    drops = [
        mode, *(str(delta(f"drop_{k}")) for k in DROP_REASONS), str(delta("oversize")),
        str(delta("subdropped")), str(int(during["streams"])), mb(during["held"]),
        str(delta("lost")), str(delta("gaps")),
    ]  # fmt: skip
    return row, drops, {"valid": valid}


DROP_REASONS = ["foreign", "unsigned", "forged", "duplicates", "stale", "malformed",
                "incomplete", "evicted"]  # fmt: skip
HEAD = ["mode", "sent", "offered/s", "rss0 MB", "peak MB", "after MB", "talker +MB",
        "valid/s", "ratio", "dups", "forged", "keyed"]  # fmt: skip
DROP_HEAD = ["mode", "foreign", "unsigned", "bad-mac", "dups", "stale", "malformed",
             "incomplete", "evicted", "oversize", "q-dropped", "streams", "held MB", "lost",
             "gaps"]  # fmt: skip


def table(head: list[str], rows: list[list[str]]) -> None:
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head))]
    for r in [head, *rows]:
        print("  ".join(f"{c:<{w}}" if i == 0 else f"{c:>{w}}" for i, (c, w) in
                        enumerate(zip(r, widths, strict=True))), flush=True)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="flood length per mode")
    parser.add_argument("--settle", type=float, default=10.0, help="wait after each flood")
    parser.add_argument("--rate", type=float, default=20000.0, help="datagrams/s offered")
    parser.add_argument("--talker-hz", type=float, default=500.0)
    parser.add_argument("--depth", type=int, default=10, help="the victim's queue depth")
    parser.add_argument("--modes", nargs="+", choices=MODES, default=MODES)
    args = parser.parse_args()
    lock = lock_domain(DOMAIN)
    folder = Path(tempfile.mkdtemp(prefix="rosl-flood-"))
    forge = Forge(DOMAIN)
    forge.talker_hz = args.talker_hz
    children: list[Child] = []
    try:
        victim_ = Child("victim", ["victim", str(args.depth)], folder)
        children.append(victim_)
        victim_.wait_ready()
        talker_ = Child("talker", ["talker", str(args.talker_hz)], folder)
        children.append(talker_)
        talker_.wait_ready()
        first = victim_.stat_after(time.monotonic() + 2.0)  # running steadily by now
        if not first["good"]:
            raise RuntimeError(f"the victim gets nothing: {victim_.stderr()[-800:]}")
        print(
            f"domain {DOMAIN}, talker {args.talker_hz:.0f} Hz, victim depth {args.depth}, "
            f"{args.seconds:.0f} s per flood, {args.settle:.0f} s settle",
            flush=True,
        )
        start = victim_.stat_after(time.monotonic())
        time.sleep(args.seconds)
        end = victim_.stat_after(time.monotonic())
        baseline = (end["good"] - start["good"]) / (end["t"] - start["t"])
        rss = memory(victim_.proc.pid).get("VmRSS", 0)
        rows = [["baseline", "0", "0", mb(rss), "", "", "", f"{baseline:.0f}", "1.00", "", "", ""]]
        drops: list[list[str]] = []
        for mode in args.modes:
            row, dropped, numbers = run_mode(mode, forge, victim_, talker_, args)
            row[8] = f"{numbers['valid'] / baseline:.2f}" if baseline else "-"
            rows.append(row)
            drops.append(dropped)
            for child in children:
                if child.proc.poll() is not None:
                    raise RuntimeError(f"{child.name} died: {child.stderr()[-2000:]}")
        print()
        table(HEAD, rows)
        print("peak: over the flood and the settle time; after: RSS at the end of the settle time;"
              " ratio: valid/s / baseline valid/s (same run)")  # fmt: skip
        print("dups/forged: delivered to the callback (must be 0); keyed: key holders' messages "
              "delivered (by design)\n")  # fmt: skip
        table(DROP_HEAD, drops)
        print("dropped by the victim's reader during each mode; q-dropped: by its subscription "
              "queue; streams, held: at the flood's end; lost: counted by the bus, gaps: real "
              "gaps in the talker's numbers the callback saw")  # fmt: skip
    finally:
        for child in children:
            child.close()
        for child in children:
            err = child.stderr()
            tracebacks = err.count("Traceback")
            print(f"{child.name}: exit {child.proc.returncode}, stderr {len(err.splitlines())} "
                  f"lines, {tracebacks} tracebacks ({child.err_path})")  # fmt: skip
        lock.close()


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "victim":
        victim(int(sys.argv[2]))
    elif len(sys.argv) > 1 and sys.argv[1] == "talker":
        talker(float(sys.argv[2]))
    else:
        main()
