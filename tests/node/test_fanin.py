"""Fan-in: many publisher processes into one subscriber, and the loss counted per publisher.

Real processes on loopback. The subscriber is stopped (SIGSTOP) while the publishers send a
burst, so everything waits in its socket, or overflows it; then it goes on and reports, per
publisher, what its callback got and what the bus counted lost (sequence gaps), with the
subscription's totals. Every publisher is heard before the burst (its stream is open) and
sends marker messages after it (a gap at the end of a burst is counted when the stream goes
on), so the counts are exact: every message up to the newest is delivered, or counted lost
(a gap), or counted dropped from the queue.
"""

from __future__ import annotations

import json
import os
import re
import signal
import socket

import pytest

BOUND = 60.0  # seconds: only a broken implementation takes this long
PUBLISHERS = 4

PUBLISHER = """
import pathlib, sys
import rosl
from std_msgs.msg import String

index, folder, count, size = int(sys.argv[1]), pathlib.Path(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
rosl.init()
node = rosl.Node(f"fanin_pub_{index}")
pub = node.create_publisher(String, "fanin", 10)
pad = "x" * size

def until(name, text):  # send ``text`` every 50 ms until the test makes the file ``name``
    for _ in range(1200):
        if (folder / name).exists():
            return
        pub.publish(String(data=f"{index}:{text}:"))
        rosl.spin_once(node, timeout_sec=0.05)

print("ready", flush=True)
until("go", "hello")  # heard before the burst: its stream is open
for n in range(count):
    pub.publish(String(data=f"{index}:{n}:{pad}"))
print("burst done", flush=True)
until("last", "final")  # the stream goes on after the burst: a gap at its end is counted
rosl.spin(node)
"""

SUBSCRIBER = """
import json, sys
import rosl
from std_msgs.msg import String

publishers, depth = int(sys.argv[1]), int(sys.argv[2])
rosl.init()
node = rosl.Node("fanin_sub")
seen = {}  # publisher index -> [received, first sequence number, last, finals]
told = False

def on_message(msg, info):
    global told
    index, text = msg.data.split(":")[:2]
    seq = info["publication_sequence_number"]
    if index not in seen:
        seen[index] = [0, seq, seq, 0, info["publisher_gid"]]
        print(f"heard {index}", flush=True)
    mine = seen[index]
    mine[0] += 1
    mine[2] = seq
    mine[3] += text == "final"
    # a gap longer than the bus's duplicate window is counted once a second message goes on
    # after it (one forged sequence number must not count as loss): two markers each
    if not told and len(seen) == publishers and all(m[3] >= 2 for m in seen.values()):
        told = True
        streams = node.participant.reader.streams
        per = {i: {"received": m[0], "lost": streams[tuple(m[4])].lost, "span": m[2] - m[1] + 1}
               for i, m in seen.items()}
        print("report " + json.dumps({"publishers": per, "lost": sub.lost,
              "dropped": sub.dropped, "received": sub.received}), flush=True)

sub = node.create_subscription(String, "fanin", on_message, depth)
print("ready", flush=True)
rosl.spin(node)
"""


def granted_rcvbuf() -> int:
    """The receive buffer the OS grants to a socket asking for 8 MiB (as rosl asks)."""
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
        return probe.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) // 2
    finally:
        probe.close()


def fan_in(spawn, tmp_path, *, count: int, size: int, depth: int, env: dict[str, str]) -> dict:
    """Run the burst; return the subscriber's report (once it heard every publisher go on)."""
    listener = spawn(SUBSCRIBER, str(PUBLISHERS), str(depth), env=env)
    listener.expect(r"^ready$", timeout=BOUND)
    talkers = [
        spawn(PUBLISHER, str(i), str(tmp_path), str(count), str(size)) for i in range(PUBLISHERS)
    ]
    for _ in range(PUBLISHERS):  # each publisher heard once, in any order
        listener.expect(r"^heard \d+$", timeout=BOUND)
    os.kill(listener.popen.pid, signal.SIGSTOP)  # the burst waits in its socket (or overflows)
    try:
        (tmp_path / "go").write_text("")
        for talker in talkers:
            talker.expect(r"^burst done$", timeout=BOUND)
    finally:
        os.kill(listener.popen.pid, signal.SIGCONT)
    report = json.loads(listener.expect(r"^report (.*)$", timeout=BOUND).group(1))
    (tmp_path / "last").write_text("")
    return report


def test_a_burst_of_many_publishers_into_a_shallow_queue_is_delivered_whole(spawn, tmp_path):
    # 4 x 200 small messages wait in the socket while the subscriber (history depth 10) is
    # stopped; reading them no faster than its queue takes them delivers every one
    if granted_rcvbuf() < 1 << 20:
        pytest.skip("the OS grants less than 1 MiB of receive buffer (net.core.rmem_max)")
    report = fan_in(spawn, tmp_path, count=200, size=32, depth=10,
                    env={"ROSL_BACKLOG_MS": "60000"})  # fmt: skip

    for counted in report["publishers"].values():
        assert counted["span"] > 200  # the burst is inside what was counted
        assert counted["received"] == counted["span"], report  # every message, none lost
        assert counted["lost"] == 0, report
    assert report["dropped"] == 0
    assert report["lost"] == 0


def test_loss_from_an_overflowing_socket_is_counted_per_publisher_exactly(spawn, tmp_path):
    # 4 x 1500 messages of 8 KB (12 MB each) overflow any receive buffer the OS grants
    report = fan_in(spawn, tmp_path, count=1500, size=8000, depth=10,
                    env={"ROSL_BACKLOG_MS": "60000"})  # fmt: skip

    publishers = report["publishers"].values()
    for counted in publishers:
        assert counted["span"] > 1500  # the burst is inside what was counted
        assert counted["lost"] > 0, report  # every one of them overflowed the buffer
        # each message up to the newest is either delivered or counted lost: nothing else
        assert counted["received"] + counted["lost"] == counted["span"], report
    assert report["lost"] == sum(p["lost"] for p in publishers)
    assert report["dropped"] == 0  # read no faster than the queue takes: the socket lost them
    assert report["received"] == sum(p["received"] for p in publishers)

    # a user sees it per publisher: topic info -v --stats, on both sides
    out, _ = spawn.module("rosl", "topic", "info", "/fanin", "-v", "--stats").finish()
    for index, counted in report["publishers"].items():
        assert f"  Lost from /fanin_pub_{index}: {counted['lost']}\n" in out, out
    lost_on_the_way = re.findall(r"^Messages sent: \d+ \(lost on the way: (\d+)\)$", out, re.M)
    assert sorted(map(int, lost_on_the_way)) == sorted(p["lost"] for p in publishers), out
    assert re.search(rf"^Messages received: \d+ \(lost: {report['lost']}, dropped: 0,", out, re.M)


def test_loss_is_counted_when_a_slow_subscriber_drops_the_backlog_for_fresh_messages(
    spawn, tmp_path
):
    # the same overflow with the default backlog bound: messages that waited in the socket
    # longer than it are read at once (keep-last keeps the newest), so some go out of the
    # queue instead; gaps and queue drops together are every lost message
    report = fan_in(spawn, tmp_path, count=1500, size=8000, depth=20, env={})

    publishers = report["publishers"].values()
    missing = 0
    for counted in publishers:
        assert counted["lost"] > 0, report
        assert counted["received"] + counted["lost"] <= counted["span"], report  # none twice
        missing += counted["span"] - counted["received"] - counted["lost"]
    assert missing <= report["dropped"], report  # what is neither came out of the queue


def test_messages_pushed_out_of_the_queue_are_counted_exactly(spawn, tmp_path):
    # the burst waits in the socket; with no backlog bound each poll reads what waits at once
    # (up to a thousand: more than the 5-deep queue holds), and the subscriber takes a poll's
    # messages of its topic in one go: every message up to the newest is delivered or counted
    # as pushed out of the queue, nothing is lost on the way
    if granted_rcvbuf() < 1 << 20:
        pytest.skip("the OS grants less than 1 MiB of receive buffer (net.core.rmem_max)")
    report = fan_in(spawn, tmp_path, count=300, size=32, depth=5, env={"ROSL_BACKLOG_MS": "0"})

    publishers = report["publishers"].values()
    assert report["lost"] == 0, report
    assert all(counted["lost"] == 0 and counted["span"] > 300 for counted in publishers), report
    missing = sum(counted["span"] - counted["received"] for counted in publishers)
    assert missing == report["dropped"] > 0, report
