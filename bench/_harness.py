"""Shared helpers for the benchmarks: raw-socket baselines, child processes, medians."""

from __future__ import annotations

import fcntl
import os
import socket
import statistics
import struct
import subprocess
import sys
import time
from pathlib import Path
from typing import IO, TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Callable

IP_MULTICAST_ALL = 49
# below the tests' domains (20-232, tests/conftest.py), so a bench beside the suite cannot collide
BENCH_DOMAIN = int(os.environ.get("ROSL_BENCH_DOMAIN", "13"))
LOCKS = Path("/tmp/rosl-test-domains")  # the test suite's domain locks


def lock_domain(domain: int) -> IO[str]:
    """Hold the test suite's lock of ``domain``, so no test picks it while a bench runs."""
    LOCKS.mkdir(exist_ok=True)
    handle = (LOCKS / f"{domain}.lock").open("w")
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        handle.close()
        raise SystemExit(f"domain {domain} is in use (set ROSL_BENCH_DOMAIN)") from None
    return handle


def raw_receiver(group: str, port: int) -> socket.socket:
    """The baseline: a plain multicast socket on loopback, 8 MiB receive buffer."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
    sock.setsockopt(socket.IPPROTO_IP, IP_MULTICAST_ALL, 0)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 8 << 20)
    sock.bind(("", port))
    mreq = struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton("127.0.0.1"))
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
    return sock


def raw_sender() -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_IF, socket.inet_aton("127.0.0.1"))
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    sock.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
    return sock


def spawn(args: list[str]) -> subprocess.Popen[str]:
    """Start a child running this Python with ``args``; it prints 'ready' when listening."""
    child = subprocess.Popen([sys.executable, *args], stdout=subprocess.PIPE, text=True)
    assert child.stdout is not None
    line = child.stdout.readline().strip()
    if line != "ready":
        child.kill()
        raise RuntimeError(f"child did not start: {line!r}")
    return child


def finish(child: subprocess.Popen[str], timeout: float = 60) -> str:
    try:
        out, _ = child.communicate(timeout=timeout)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    return out.strip()


def median_of(runs: int, measure: Callable[[], float]) -> float:
    return statistics.median(measure() for _ in range(runs))


def wait_quiet(limit: float = 0.25, timeout: float = 20.0) -> None:
    """Wait (bounded) until the machine's load is low, so runs compare fairly."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        with open("/proc/loadavg") as f:
            if float(f.read().split()[0]) < limit * os.cpu_count():
                return
        time.sleep(0.5)
