"""``rosl bag play``'s controls: the playback clock and the keyboard.

The clock is bag time running at a rate from a wall-clock moment; pausing freezes it,
changing the rate or jumping restarts it from where it is. On a terminal, SPACE pauses and
resumes, → asks for the next message while paused, ↑/↓ change the rate by 10% — read in
cbreak mode, and the terminal's settings are restored on exit.
"""

from __future__ import annotations

import os
import select
import sys
import time
from typing import Any

NS = 1_000_000_000
HINTS = (  # what ros2 bag play prints when it reads keys
    "Adding keyboard callbacks.",
    "Press SPACE for Pause/Resume",
    "Press CURSOR_RIGHT for Play Next Message",
    "Press CURSOR_UP for Increase Rate 10%",
    "Press CURSOR_DOWN for Decrease Rate 10%",
)
KEYS = {  # key bytes -> command
    b" ": "pause",
    b"\x1b[C": "next",
    b"\x1b[A": "faster",
    b"\x1b[B": "slower",
}


class Timeline:
    """The playback clock: bag time that runs at ``rate`` and can pause, step and jump."""

    def __init__(self, start_ns: int, rate: float) -> None:
        self.rate = rate
        self.paused = False
        self._bag = start_ns
        self._wall = time.monotonic_ns()

    def now(self) -> int:
        """The bag time (ns) the playback has reached."""
        if self.paused:
            return self._bag
        return self._bag + int((time.monotonic_ns() - self._wall) * self.rate)

    def jump(self, bag_ns: int) -> None:
        """Go on from ``bag_ns`` now."""
        self._bag, self._wall = bag_ns, time.monotonic_ns()

    def set_paused(self, paused: bool) -> None:
        """Freeze the clock where it is, or let it run on from there."""
        self.jump(self.now())
        self.paused = paused

    def set_rate(self, rate: float) -> None:
        """Run at ``rate`` from where the clock is."""
        self.jump(self.now())
        self.rate = rate

    def seconds_until(self, bag_ns: int) -> float:
        """Wall seconds until the clock reaches ``bag_ns`` (infinite while paused)."""
        if self.paused:
            return float("inf")
        return (bag_ns - self.now()) / self.rate / NS


class Keyboard:
    """SPACE and the arrow keys, read from a terminal in cbreak mode (restored on exit)."""

    def __init__(self, enabled: bool) -> None:
        self.fd = sys.stdin.fileno() if enabled and sys.stdin.isatty() else -1
        self._saved: Any = None

    @property
    def active(self) -> bool:
        """Whether keys are read (stdin is a terminal and controls are enabled)."""
        return self.fd >= 0

    def __enter__(self) -> Keyboard:
        if self.active:
            import termios
            import tty

            self._saved = termios.tcgetattr(self.fd)
            tty.setcbreak(self.fd)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._saved is not None:
            import termios

            termios.tcsetattr(self.fd, termios.TCSADRAIN, self._saved)
            self._saved = None

    def read(self, timeout: float) -> list[str]:
        """Wait up to ``timeout`` for keys; return the commands typed."""
        ready, _, _ = select.select([self.fd], [], [], max(0.0, timeout))
        if not ready:
            return []
        data = os.read(self.fd, 64)
        commands = []
        while data:
            for key, command in KEYS.items():
                if data.startswith(key):
                    commands.append(command)
                    data = data[len(key) :]
                    break
            else:
                data = data[1:]
        return commands
