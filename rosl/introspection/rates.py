"""``topic hz/bw/delay``: statistics timed at the socket, printed as ros2cli prints them.

``hz`` and ``bw`` tap the bus directly: each datagram's receive time is taken right after it
is read, and messages are not decoded (only ``--filter`` needs decoding), so rates stay right
at kilohertz where ros2's Python callbacks fall behind. Sequence numbers give the true count
of messages lost on the way, printed when there is loss.
"""

from __future__ import annotations

import math
import time
from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.bus.header import Kind, topic_hash
from rosl.bus.wire import DUP_WINDOW, LOSS_WINDOW

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.wire import Delivery

NS = 1e9
MAX_PUBLISHERS = 4096  # publisher streams followed for loss


@dataclass(slots=True)
class Window:
    """Inter-arrival times (ns) and sizes of one topic's recent messages."""

    size: int
    last: int = -1
    deltas: deque[int] = field(default_factory=deque)
    sizes: deque[int] = field(default_factory=deque)
    stamps: deque[int] = field(default_factory=deque)
    count: int = 0
    printed_at: int = 0
    lost: int = 0
    last_seq: dict[tuple[int, int], int] = field(default_factory=dict)

    def add(self, received: int, size: int, sender: int, endpoint: int, seq: int) -> None:
        """Record one message."""
        if self.last >= 0:
            self.deltas.append(received - self.last)
            if len(self.deltas) > self.size:
                self.deltas.popleft()
        self.last = received
        self.sizes.append(size)
        self.stamps.append(received)
        if len(self.sizes) > self.size:
            self.sizes.popleft()
            self.stamps.popleft()
        self.count += 1
        self.note_seq(sender, endpoint, seq)

    def note_seq(self, sender: int, endpoint: int, seq: int) -> None:
        """Follow one publisher's sequence numbers: a gap is lost messages."""
        key = (sender, endpoint)
        previous = self.last_seq.get(key)
        if previous is None:
            if len(self.last_seq) < MAX_PUBLISHERS:  # made-up senders must not grow the table
                self.last_seq[key] = seq
            return
        step = (seq - previous) & 0xFFFFFFFF
        if 0 < step <= LOSS_WINDOW:
            self.lost += step - 1
            self.last_seq[key] = seq
        elif (previous - seq) & 0xFFFFFFFF >= DUP_WINDOW:  # a jump: a new segment, not loss
            self.last_seq[key] = seq


class Tap:
    """A bus-level handler collecting receive times of one topic, with no decoding.

    Args:
        topic: the topic name.
        window: how many messages the statistics cover (``-w``).
        accept: an optional predicate on the delivery (``--filter`` decodes here).
    """

    def __init__(
        self, topic: str, window: int, accept: Callable[[Delivery], bool] | None = None
    ) -> None:
        self.topic = topic
        self.hash = topic_hash(topic)
        self.window = Window(window)
        self.accept = accept

    def deliver(self, delivery: Delivery) -> None:
        """Take one delivery from the participant."""
        if delivery.kind != Kind.DATA:
            return
        if self.accept is not None and not self.accept(delivery):
            # filtered out: neither counted nor lost (ros2 skips it in the callback)
            self.window.note_seq(delivery.sender, delivery.endpoint, delivery.seq)
            return
        self.window.add(
            delivery.received, len(delivery.payload), delivery.sender, delivery.endpoint,
            delivery.seq,
        )  # fmt: skip


def hz_stats(window: Window) -> tuple[float, float, float, float, int] | None:
    """(rate Hz, min s, max s, std dev s, window) or None before two messages."""
    deltas = window.deltas
    if not deltas:
        return None
    n = len(deltas)
    mean = sum(deltas) / n
    std = math.sqrt(sum((d - mean) ** 2 for d in deltas) / n)
    rate = NS / mean if mean > 0 else 0.0
    return rate, min(deltas) / NS, max(deltas) / NS, std / NS, n


def due(window: Window, period_ns: int = 1_000_000_000) -> bool:
    """Whether a new report is due: a message arrived a second after the last report."""
    if window.last < 0:
        return False
    if window.printed_at == 0:
        window.printed_at = window.last
        return False
    if window.last < window.printed_at + period_ns:
        return False
    window.printed_at = window.last
    return True


def hz_text(window: Window) -> str | None:
    """ros2's two lines for one topic (plus a loss line when messages were lost)."""
    stats = hz_stats(window)
    if stats is None:
        return None
    rate, low, high, std, n = stats
    text = (
        f"average rate: {rate:.3f}\n\tmin: {low:.3f}s max: {high:.3f}s std dev: {std:.5f}s "
        f"window: {n}"
    )
    if window.lost:
        text += f"\n\tlost: {window.lost} message(s) (sequence gaps seen by rosl)"
    return text


def ascii_table(header: list[str], rows: list[list[str]]) -> str:
    """ros2cli's table for several topics (centred headers, '=' rule, 3-space gaps)."""
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    head = "   ".join(h.center(w) for h, w in zip(header, widths, strict=True))
    body = "\n".join(
        "   ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) for row in rows
    )
    return f"{head}\n{'=' * (sum(widths) + 3 * (len(header) - 1))}\n{body}\n"


def hz_table(windows: dict[str, Window]) -> str | None:
    """The table ``ros2 topic hz A B`` prints."""
    rows = []
    for topic, window in windows.items():
        stats = hz_stats(window)
        if stats is None:
            continue
        rate, low, high, std, n = stats
        rows.append([topic, f"{rate:.4}", f"{low:.4}", f"{high:.4}", f"{std:.4}", str(n)])
    if not rows:
        return "no new messages"
    return ascii_table(["topic", "rate", "min_delta", "max_delta", "std_dev", "window"], rows)


def _bytes(value: float) -> str:
    if value < 1000:
        return f"{value:.0f} B"
    if value < 1_000_000:
        return f"{value / 1000:.2f} KB"
    return f"{value / 1_000_000:.2f} MB"


def bw_text(window: Window, now_ns: int | None = None) -> str | None:
    """ros2's bandwidth lines: the window's bytes over the time since its first message.

    As ros2's ``bw`` does, the rate divides by ``now - first`` (not ``last - first``), so a
    topic that stops publishing shows its bandwidth falling.
    """
    sizes, stamps = window.sizes, window.stamps
    if len(sizes) < 2:
        return None
    now = time.time_ns() if now_ns is None else now_ns  # receive times are time.time_ns()
    span = (now - stamps[0]) / NS
    if span <= 0:
        return None
    total = sum(sizes)
    rate = total / span
    mean = total / len(sizes)
    return (
        f"{_bytes(rate)}/s from {len(sizes)} messages\n\tMessage size mean: {_bytes(mean)} "
        f"min: {_bytes(min(sizes))} max: {_bytes(max(sizes))}"
    )


@dataclass(slots=True)
class Delays:
    """Delays (receive time minus header.stamp) of recent messages, in ns."""

    size: int
    values: deque[int] = field(default_factory=deque)
    printed_at: int = 0
    last: int = -1

    def add(self, received: int, stamp_ns: int) -> None:
        """Record one message's delay."""
        self.values.append(received - stamp_ns)
        if len(self.values) > self.size:
            self.values.popleft()
        self.last = received


def delay_text(delays: Delays) -> str | None:
    """ros2's delay lines."""
    values = delays.values
    if not values:
        return None
    n = len(values)
    mean = sum(values) / n
    std = math.sqrt(sum((v - mean) ** 2 for v in values) / n)
    return (
        f"average delay: {mean / NS:.3f}\n\tmin: {min(values) / NS:.3f}s "
        f"max: {max(values) / NS:.3f}s std dev: {std / NS:.5f}s window: {n}"
    )


def header_stamp_ns(message: Any) -> int | None:
    """A message's header.stamp in ns, or None when it has no header."""
    header = getattr(message, "header", None)
    stamp = getattr(header, "stamp", None)
    if stamp is None:
        return None
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
