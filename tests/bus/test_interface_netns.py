"""ROSL_INTERFACE across network namespaces, and a clear error where multicast cannot work.

The namespace tests need ``ip netns`` (root, or CAP_NET_ADMIN); they skip with the reason
otherwise. Everything they send stays inside namespaces the test creates and deletes.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from typing import TYPE_CHECKING

import pytest

from rosl.bus.errors import BusError
from rosl.bus.multicast import FIX_HINT, Addressing, MulticastTransport
from rosl.graph.announce import SELFTEST_S, Discovery
from tests.bus.helpers import LISTENER, PROBE, TALKER, Lines, good_count, wait_exit
from tests.conftest import wait_until

if TYPE_CHECKING:
    from collections.abc import Iterator, Sequence

    from tests.conftest import Processes

TOPIC = "/netns_chatter"


def ip(*args: str, check: bool = True) -> subprocess.CompletedProcess[str]:
    return subprocess.run(["ip", *args], capture_output=True, text=True, timeout=15, check=check)


class Namespaces:
    """Network namespaces (and their veths) made for one test; all deleted afterwards."""

    def __init__(self, processes: Processes) -> None:
        self.processes = processes
        self.suffix = os.urandom(3).hex()
        self.created: list[str] = []

    def add(self, role: str) -> str:
        name = f"rosl-test-{self.suffix}-{role}"
        ip("netns", "add", name)
        self.created.append(name)
        return name

    def run(
        self, namespace: str, args: Sequence[str], env: dict[str, str] | None = None
    ) -> subprocess.Popen[str]:
        """Start a process inside a namespace (``ip netns exec`` becomes that process)."""
        return self.processes.start(["ip", "netns", "exec", namespace, *args], env=env)

    def close(self) -> None:
        self.processes.close()  # nothing may keep a namespace alive once it is deleted
        for name in reversed(self.created):
            ip("netns", "del", name, check=False)


@pytest.fixture
def netns(processes: Processes) -> Iterator[Namespaces]:
    if shutil.which("ip") is None:
        pytest.skip("needs the `ip` command (iproute2)")
    spaces = Namespaces(processes)
    try:
        spaces.add("probe")
    except subprocess.CalledProcessError as err:
        pytest.skip(f"cannot create network namespaces here: {err.stderr.strip()}")
    try:
        yield spaces
    finally:
        spaces.close()


def veth_pair(netns: Namespaces) -> tuple[str, str, str, str]:
    """Two namespaces joined by a veth pair with 10.77.x.1/24 and .2/24 and a multicast route.

    Returns:
        (namespace A, veth in A, namespace B, veth in B); lo stays down in both, so the
        traffic can only use the veth.
    """
    a, b = netns.add("a"), netns.add("b")
    va, vb = f"rv{netns.suffix}a", f"rv{netns.suffix}b"
    subnet = int(netns.suffix[:2], 16) % 250 + 1
    ip("link", "add", va, "type", "veth", "peer", "name", vb)
    ip("link", "set", va, "netns", a)
    ip("link", "set", vb, "netns", b)
    for space, dev, host in ((a, va, 1), (b, vb, 2)):
        ip("-n", space, "addr", "add", f"10.77.{subnet}.{host}/24", "dev", dev)
        ip("-n", space, "link", "set", dev, "up")
        ip("-n", space, "route", "add", "224.0.0.0/4", "dev", dev)
    return a, va, b, vb


def diagnose(*pairs: tuple[str, str]) -> str:
    """Link counters and multicast memberships, for failure messages."""
    report = []
    for space, dev in pairs:
        for args in (["-s", "link", "show", dev], ["maddr", "show", "dev", dev], ["route"]):
            result = ip("-n", space, *args, check=False)
            report.append(f"$ ip -n {space} {' '.join(args)}\n{result.stdout}{result.stderr}")
        for args in (["cat", "/proc/net/snmp"], ["ss", "-uanm"]):
            result = ip("netns", "exec", space, *args, check=False)
            report.append(f"$ {' '.join(args)} in {space}\n{result.stdout}{result.stderr}")
    return "\n".join(report)


def python(code: str, *args: str) -> list[str]:
    return [sys.executable, "-c", code, *args]


def stop(child: subprocess.Popen[str]) -> None:
    if child.poll() is None:
        child.send_signal(2)
    if wait_exit(child, 10.0) is None:
        child.kill()


def test_publisher_and_subscriber_in_two_namespaces(netns: Namespaces, domain_id: int) -> None:
    a, va, b, vb = veth_pair(netns)
    talker = netns.run(a, python(TALKER, "netns_talker", TOPIC), env={"ROSL_INTERFACE": va})
    listener = netns.run(b, python(LISTENER, "netns_listener", TOPIC), env={"ROSL_INTERFACE": vb})
    talker_out, talker_err = Lines(talker.stdout), Lines(talker.stderr)
    out, err = Lines(listener.stdout), Lines(listener.stderr)
    try:
        assert talker_out.wait_line("up", 20.0), f"talker: {talker_err.rest(1.0)}"
        assert out.wait_line("up", 20.0), f"listener: {err.rest(1.0)}"
        if not out.wait_for(lambda lines: good_count(lines) >= 20, 20.0):
            network = diagnose((a, va), (b, vb))
            stop(listener)
            stop(talker)
            pytest.fail(
                f"nothing crossed the veth: listener {out.rest(2.0)[-3:]} {err.rest(2.0)[-5:]}, "
                f"talker {talker_out.rest(2.0)[-3:]} {talker_err.rest(2.0)[-5:]}\n{network}"
            )
        # discovery crosses too: a fresh process next to the listener sees the talker
        probe = netns.run(b, python(PROBE, "/netns_talker"), env={"ROSL_INTERFACE": vb})
        probe_out, probe_err = Lines(probe.stdout), Lines(probe.stderr)
        probe_out.wait_for(lambda lines: any(x in ("found", "missing") for x in lines), 40.0)
        assert "found" in probe_out.lines, f"{probe_out.lines} {probe_err.rest(1.0)}"
    finally:
        stop(listener)
        stop(talker)
    assert "Traceback" not in "\n".join(err.rest(2.0) + talker_err.rest(2.0))


def test_interface_given_by_address_works_too(netns: Namespaces, domain_id: int) -> None:
    a, va, b, vb = veth_pair(netns)
    subnet = int(netns.suffix[:2], 16) % 250 + 1
    talker = netns.run(
        a, python(TALKER, "addr_talker", TOPIC), env={"ROSL_INTERFACE": f"10.77.{subnet}.1"}
    )
    listener = netns.run(
        b, python(LISTENER, "addr_listener", TOPIC), env={"ROSL_INTERFACE": f"10.77.{subnet}.2"}
    )
    out, err = Lines(listener.stdout), Lines(listener.stderr)
    talker_err = Lines(talker.stderr)
    try:
        assert out.wait_for(lambda lines: good_count(lines) >= 20, 30.0), (
            f"listener {err.lines[-5:]}, talker {talker_err.lines[-5:]}\n{diagnose((a, va), (b, vb))}"
        )
    finally:
        stop(listener)
        stop(talker)


SOCKETS_RECEIVER = r"""
import json, select, sys, time
from rosl.bus.multicast import Addressing
from rosl.bus.multicast import MulticastTransport
from rosl.bus.wire import Reader

domain, address, expected = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
channels = [int(c) for c in sys.argv[4].split(",")]
transport = MulticastTransport(Addressing(domain, address, 1))
sockets = {c: transport.open(c) for c in channels}
reader = Reader()
reader.want_all = True
counts = {c: 0 for c in channels}
print("ready", flush=True)
deadline = time.monotonic() + 60
heard = None  # 5 s of silence after the last datagram means the sender is done
while time.monotonic() < deadline and sum(counts.values()) < expected:
    if heard is not None and time.monotonic() - heard > 5.0:
        break
    ready, _, _ = select.select(list(sockets.values()), [], [], 0.1)
    for channel, sock in sockets.items():
        if sock in ready:
            heard = time.monotonic()
            got = []
            while reader.drain(sock.recv, got):
                pass
            counts[channel] += len(got)
print(json.dumps(counts), flush=True)
transport.close()
"""

SOCKETS_SENDER = r"""
import sys, time
from rosl.bus.multicast import Addressing
from rosl.bus.multicast import MulticastTransport
from rosl.bus.wire import Writer

domain, address, channel, flows, each = (int(sys.argv[1]), sys.argv[2], int(sys.argv[3]),
                                         int(sys.argv[4]), int(sys.argv[5]))
# every transport has its own sending socket, so its own source port: a flow of its own
writers = [
    Writer(MulticastTransport(Addressing(domain, address, 1)), 1000 + n, 1, "/flow", "a/b/C",
           channel=channel)
    for n in range(flows)
]
for _ in range(each):
    for writer in writers:
        writer.send(b"payload")
    time.sleep(0.005)
print("sent", flush=True)
"""


def test_each_channel_socket_gets_only_its_group_across_a_veth(
    netns: Namespaces, domain_id: int
) -> None:
    """A datagram for one group must reach that group's socket, and no other channel's.

    rosl binds every channel socket to 0.0.0.0:port with SO_REUSEPORT and tells them apart by
    group membership (IP_MULTICAST_ALL=0). Over loopback that holds; datagrams arriving on a
    real interface must be delivered by membership too, whatever their source port.
    """
    a, _, b, _ = veth_pair(netns)
    subnet = int(netns.suffix[:2], 16) % 250 + 1
    target, others = 21, [0, 3, 14, 18, 23, 26, 54]  # like a node: discovery + 7 channels
    flows, each = 16, 20
    receiver = netns.run(
        b,
        python(SOCKETS_RECEIVER, str(domain_id), f"10.77.{subnet}.2", str(flows * each),
               ",".join(map(str, [*others, target]))),
    )  # fmt: skip
    out, err = Lines(receiver.stdout), Lines(receiver.stderr)
    assert out.wait_line("ready", 20.0), err.rest(1.0)
    sender = netns.run(
        a,
        python(SOCKETS_SENDER, str(domain_id), f"10.77.{subnet}.1", str(target), str(flows),
               str(each)),
    )  # fmt: skip
    sent = Lines(sender.stdout)
    assert sent.wait_line("sent", 20.0), Lines(sender.stderr).rest(1.0)
    line = out.wait_line("{", 70.0)
    assert line is not None, err.rest(1.0)
    counts = {int(k): v for k, v in json.loads(line).items()}
    misdelivered = {c: n for c, n in counts.items() if c != target and n}
    assert not misdelivered, (
        f"datagrams for group .{target} were delivered to other channels' sockets "
        f"{misdelivered} (and {counts[target]} to the right one)"
    )
    assert counts[target] == flows * each


# --- no usable multicast: one clear line ------------------------------------------------------

NODE_SPINS = r"""
import time
import rosl

rosl.init()
node = rosl.Node("lonely")
end = time.monotonic() + 3
while time.monotonic() < end:
    rosl.spin_once(node, timeout_sec=0.1)
rosl.shutdown()
print("spun", flush=True)
"""


def assert_clear_multicast_line(line: str) -> None:
    assert "multicast" in line
    assert "ip link set lo up" in line
    assert "ROSL_INTERFACE" in line


@pytest.mark.parametrize("args", [["topic", "list"], ["node", "list"]], ids=" ".join)
def test_cli_with_loopback_down_prints_one_line(
    netns: Namespaces, domain_id: int, args: list[str]
) -> None:
    space = netns.add("lodown")  # a fresh namespace: lo exists but is down
    child = netns.run(space, [sys.executable, "-m", "rosl", *args])
    out, err = Lines(child.stdout), Lines(child.stderr)
    code = wait_exit(child, 20.0)
    lines = [x for x in err.rest(5.0) if x.strip()]
    assert code not in (0, None), f"exit {code}; stdout {out.rest(1.0)}"
    assert len(lines) == 1, lines
    assert "Traceback" not in lines[0]
    assert_clear_multicast_line(lines[0])


def test_node_with_loopback_down_fails_with_the_multicast_hint(
    netns: Namespaces, domain_id: int
) -> None:
    space = netns.add("lodown")
    child = netns.run(space, python(NODE_SPINS))
    out, err = Lines(child.stdout), Lines(child.stderr)
    code = wait_exit(child, 20.0)
    lines = [x for x in err.rest(5.0) if x.strip()]
    assert "spun" not in out.rest(1.0), "the node ran as if multicast worked"
    assert code not in (0, None)
    # a user's script shows Python's traceback (only rosl's CLI turns errors into one line);
    # what rosl owes is an error whose message is one line naming multicast and the fix
    assert lines, "failed silently"
    last = lines[-1]
    assert last.startswith("rosl.bus.errors.BusError: "), lines[-5:]
    assert_clear_multicast_line(last)


def test_unknown_interface_in_a_namespace_names_it(netns: Namespaces, domain_id: int) -> None:
    space = netns.add("noif")
    child = netns.run(
        space, [sys.executable, "-m", "rosl", "topic", "list"], env={"ROSL_INTERFACE": "nosuch7"}
    )
    err = Lines(child.stderr)
    code = wait_exit(child, 20.0)
    lines = [x for x in err.rest(5.0) if x.strip()]
    assert code not in (0, None)
    assert len(lines) == 1, lines
    assert "ROSL_INTERFACE=nosuch7" in lines[0]


# --- the loopback self-test (no namespace needed) ---------------------------------------------


class MuteTransport(MulticastTransport):
    """A real transport whose sends vanish: our own datagrams never come back."""

    def send(self, channel: int, parts: object) -> None:  # type: ignore[override]
        pass


def test_selftest_reports_one_line_when_own_datagrams_never_return(
    domain_id: int, capsys: pytest.CaptureFixture[str]
) -> None:
    transport = MuteTransport(Addressing(domain_id))
    discovery = Discovery(transport, 0x5E1F7E57, lambda: [])
    try:
        discovery.start()
        qid = discovery.query()
        with pytest.raises(BusError) as caught:
            discovery.wait_complete(qid, timeout=0.2)
        message = str(caught.value)
        assert "\n" not in message
        assert "multicast does not work here" in message
        assert f"239.255.{domain_id}.0:{17400 + domain_id}" in message
        assert FIX_HINT in message

        seen: list[str] = []

        def warned() -> bool:
            seen.extend(capsys.readouterr().err.splitlines())
            return any("multicast does not work here" in x for x in seen)

        assert wait_until(warned, timeout=SELFTEST_S + 15.0)
        time.sleep(0.5)  # it is said once, not every period
        warned()
        lines = [x for x in seen if x.strip()]
        assert len(lines) == 1, lines
        assert lines[0].startswith("rosl: error: multicast does not work here")
        assert FIX_HINT in lines[0]
        assert not discovery.loopback_ok.is_set()
    finally:
        discovery.stop()
        transport.close()
