"""Pacing of fragmented messages, so one big message does not overrun its receivers.

UDP has no flow control: a process can write a 16 MB message into the kernel faster than a
Python receiver drains its socket, and one lost fragment loses the whole message. A token
bucket lets bursts up to ``burst`` bytes (well under a receive buffer) through at once and
holds fragmented traffic to ``rate`` bytes/s beyond that, sleeping (not spinning) to do so.
Single-datagram messages are never paced.
"""

from __future__ import annotations

import os
import threading
import time

# bytes/s: loopback, network. 300 MB/s on loopback: a Python receiver on a busy 2-core machine
# keeps up with 16 MiB messages at this pace (at 600 MB/s it lost some under load; the OS caps
# the receive buffer at 8 MiB, ~25 ms of slack here)
DEFAULT_RATE = {True: 3.0e8, False: 100.0e6}
DEFAULT_BURST = 1024 * 1024


class Pacer:
    """A token bucket over bytes."""

    def __init__(self, rate: float, burst: int = DEFAULT_BURST) -> None:
        self.rate = rate
        self.burst = burst
        self._tokens = float(burst)
        self._last = time.perf_counter()
        self._lock = threading.Lock()

    def spend(self, size: int) -> None:
        """Take ``size`` bytes from the bucket, sleeping first if it is empty."""
        with self._lock:
            now = time.perf_counter()
            self._tokens = min(self.burst, self._tokens + (now - self._last) * self.rate)
            self._last = now
            self._tokens -= size
            debt = -self._tokens / self.rate if self._tokens < 0 else 0.0
        if debt > 0.0002:  # sleep in steps the OS can honour; smaller debts carry over
            time.sleep(debt)


def pacer_from_env(loopback: bool) -> Pacer:
    """Build the pacer for a transport: ``ROSL_MAX_RATE`` (bytes/s) overrides the default."""
    text = os.environ.get("ROSL_MAX_RATE", "").strip()
    try:
        rate = float(text) if text else DEFAULT_RATE[loopback]
    except ValueError:
        rate = DEFAULT_RATE[loopback]
    return Pacer(max(rate, 1e5))
