"""``rosl multicast send|receive``: ROS 2's one-datagram check, as real processes on loopback."""

from __future__ import annotations

import contextlib
import fcntl
import re
import socket
import struct
import subprocess
import time
from typing import TYPE_CHECKING

import pytest

from tests.cli.conftest import Result, assert_user_error, run
from tests.conftest import LOCK_DIR
from tests.graph.support import Watched

if TYPE_CHECKING:
    from collections.abc import Iterator

    from tests.conftest import Processes

RECEIVED = r"^Received from 127\.0\.0\.1:(\d+): 'Hello World!'$"


def port_of(domain_id: int) -> int:
    """A port no other test uses now: the test's locked domain picks it."""
    return 40000 + domain_id


def start_receiver(processes: Processes, *args: str, env: dict[str, str] | None = None) -> Watched:
    """``rosl multicast receive ARGS``, once it has joined the group (its first line)."""
    child = Watched(processes.rosl("multicast", "receive", "--timeout", "30", *args, env=env))
    assert child.wait_for(r"^Waiting for UDP multicast datagram\.\.\.$", timeout=30.0), child.text(
        "out"
    ) + child.text("err")
    return child


def finish(child: Watched) -> Result:
    """Wait (bounded) for a receiver that should be done; its exit code and output."""
    with contextlib.suppress(subprocess.TimeoutExpired):
        child.child.wait(timeout=20)
    code = child.interrupt()  # Ctrl-C only if still waiting; joins the output readers
    return Result(-1 if code is None else code, child.text("out"), child.text("err"))


def test_receive_prints_the_datagram_send_sent_and_exits(
    processes: Processes, domain_id: int
) -> None:
    port = str(port_of(domain_id))
    receiver = start_receiver(processes, "--port", port)

    sent = run(processes, "multicast", "send", "--port", port)

    assert sent.code == 0, sent
    assert sent.out == "Sending one UDP multicast datagram...\n"
    received = finish(receiver)
    assert received.code == 0, received
    assert received.out.splitlines()[0] == "Waiting for UDP multicast datagram..."
    assert re.match(RECEIVED, received.out.splitlines()[1]), received.out
    assert received.err == ""


def test_a_named_loopback_interface_is_used_as_rosl_interface_says(
    processes: Processes, domain_id: int
) -> None:
    port = str(port_of(domain_id))
    receiver = start_receiver(processes, "--port", port, env={"ROSL_INTERFACE": "lo"})

    sent = run(processes, "multicast", "send", "--port", port, "--ttl", "1")

    assert sent.code == 0, sent
    received = finish(receiver)
    assert received.code == 0, received
    assert re.match(RECEIVED, received.out.splitlines()[-1]), received.out


@pytest.fixture
def ros2_group_and_port() -> Iterator[None]:
    """Hold 225.0.0.1:49150 (ROS 2's fixed check address) for this test alone, bounded."""
    LOCK_DIR.mkdir(exist_ok=True)
    with open(LOCK_DIR / "ros2-multicast.lock", "w") as handle:
        deadline = time.monotonic() + 60
        while True:
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except OSError:
                assert time.monotonic() < deadline, "225.0.0.1:49150 stayed taken for 60 s"
                time.sleep(0.1)
        yield


def raw_listener(group: str, port: int) -> socket.socket:
    """A plain socket joined to ``group:port`` on 127.0.0.1, as any multicast tool would."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
    sock.bind((group, port))
    membership = struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton("127.0.0.1"))
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
    sock.settimeout(20)
    return sock


def test_by_default_the_check_uses_ros2s_group_and_port(
    processes: Processes, ros2_group_and_port: None
) -> None:
    receiver = start_receiver(processes)
    other_tool = raw_listener("225.0.0.1", 49150)
    try:
        sent = run(processes, "multicast", "send")
        data, (host, _) = other_tool.recvfrom(4096)
    finally:
        other_tool.close()

    assert sent.code == 0, sent
    assert (data, host) == (b"Hello World!", "127.0.0.1")
    received = finish(receiver)
    assert received.code == 0, received
    assert re.match(RECEIVED, received.out.splitlines()[-1]), received.out


def test_receive_with_a_timeout_and_nothing_sent_is_one_line(
    processes: Processes, domain_id: int
) -> None:
    port = port_of(domain_id)
    result = run(processes, "multicast", "receive", "--port", str(port), "--timeout", "0.3")

    assert result.out == "Waiting for UDP multicast datagram...\n"
    assert_user_error(result, f"no UDP multicast datagram on 225.0.0.1:{port}", "within 0.3 s")


@pytest.mark.parametrize(
    ("args", "env", "fragment"),
    [
        (["--group", "10.1.2.3"], {}, "--group 10.1.2.3: not a multicast address"),
        (["--group", "nowhere"], {}, "--group nowhere: not an IPv4 address"),
        ([], {"ROSL_INTERFACE": "no_such_if0"}, "ROSL_INTERFACE=no_such_if0: no such interface"),
    ],
    ids=["not-multicast", "not-an-address", "unknown-interface"],
)
def test_a_bad_group_or_interface_is_one_line_and_nothing_is_sent(
    processes: Processes, args: list[str], env: dict[str, str], fragment: str
) -> None:
    child = processes.rosl("multicast", "send", *args, env={"NO_COLOR": "1", **env})
    out, err = child.communicate(timeout=30)

    assert out == ""
    assert_user_error(Result(child.returncode, out, err), fragment)
