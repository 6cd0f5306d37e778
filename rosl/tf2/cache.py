"""What one frame's edge to its parent was over time: tf2's TimeCache and StaticCache.

A dynamic edge keeps its transforms, oldest first, for ``cache_time_ns`` behind the newest
(10 s by default); asked for a time between two of them it interpolates, outside them it
reports the extrapolation in tf2's words. A static edge holds one transform, valid at every
time. Time 0 means "the latest".
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rosl.tf2.transform import Transform

DEFAULT_CACHE_TIME_NS = 10_000_000_000


def seconds_text(stamp_ns: int) -> str:
    """A time as tf2 prints it in messages: seconds with six decimals."""
    return f"{stamp_ns / 1e9:.6f}"


@dataclass(frozen=True, slots=True)
class Entry:
    """The transform parent←child at ``stamp_ns``."""

    stamp_ns: int
    parent: str
    transform: Transform


class TimeCache:
    """A dynamic edge's recent transforms, sorted by stamp."""

    static = False

    def __init__(self, cache_time_ns: int = DEFAULT_CACHE_TIME_NS) -> None:
        self.cache_time_ns = cache_time_ns
        self._entries: list[Entry] = []
        self._stamps: list[int] = []

    def insert(self, entry: Entry) -> bool:
        """Keep ``entry``; False when it is older than what the cache keeps (tf2's TF_OLD_DATA)."""
        latest = self._stamps[-1] if self._stamps else 0
        self._prune(latest)
        if self._entries and entry.stamp_ns < latest - self.cache_time_ns:
            return False
        at = bisect.bisect_right(self._stamps, entry.stamp_ns)
        same = at
        while same > 0 and self._stamps[same - 1] == entry.stamp_ns:
            same -= 1
            if self._entries[same] == entry:
                return True  # already held
        self._entries.insert(at, entry)
        self._stamps.insert(at, entry.stamp_ns)
        return True

    def _prune(self, latest: int) -> None:
        cut = bisect.bisect_left(self._stamps, latest - self.cache_time_ns)
        if cut:
            del self._entries[:cut]
            del self._stamps[:cut]

    def at(self, time_ns: int) -> tuple[Entry | None, str]:
        """The transform at ``time_ns`` (interpolated), or None and tf2's reason."""
        entries = self._entries
        if not entries:
            return None, ""
        if time_ns == 0:
            return entries[-1], ""
        if len(entries) == 1:
            if entries[0].stamp_ns == time_ns:
                return entries[0], ""
            return None, (
                f"Lookup would require extrapolation at time {seconds_text(time_ns)}, but only "
                f"time {seconds_text(entries[0].stamp_ns)} is in the buffer"
            )
        earliest, latest = entries[0].stamp_ns, entries[-1].stamp_ns
        if time_ns > latest:
            return None, (
                "Lookup would require extrapolation into the future.  Requested time "
                f"{seconds_text(time_ns)} but the latest data is at time {seconds_text(latest)}"
            )
        if time_ns < earliest:
            return None, (
                "Lookup would require extrapolation into the past.  Requested time "
                f"{seconds_text(time_ns)} but the earliest data is at time "
                f"{seconds_text(earliest)}"
            )
        later = bisect.bisect_left(self._stamps, time_ns)
        if self._stamps[later] == time_ns:
            return entries[later], ""
        before, after = entries[later - 1], entries[later]
        if before.parent != after.parent:
            return before, ""
        ratio = (time_ns - before.stamp_ns) / (after.stamp_ns - before.stamp_ns)
        return replace(before, transform=before.transform.interpolate(after.transform, ratio)), ""

    def latest(self) -> tuple[int, str] | None:
        """(stamp, parent) of the newest transform, None when empty."""
        return (self._entries[-1].stamp_ns, self._entries[-1].parent) if self._entries else None

    @property
    def newest_ns(self) -> int:
        """The newest stamp (0 when empty)."""
        return self._stamps[-1] if self._stamps else 0

    @property
    def oldest_ns(self) -> int:
        """The oldest stamp kept (0 when empty)."""
        return self._stamps[0] if self._stamps else 0

    def __len__(self) -> int:
        return len(self._entries)

    def clear(self) -> None:
        """Forget everything (the frame stays known)."""
        self._entries.clear()
        self._stamps.clear()


class StaticCache:
    """A static edge: one transform, valid at every time (its stamps count as 0)."""

    static = True

    def __init__(self, entry: Entry) -> None:
        self.entry = entry

    def insert(self, entry: Entry) -> bool:
        """Replace the transform."""
        self.entry = entry
        return True

    def at(self, time_ns: int) -> tuple[Entry | None, str]:
        """The transform, stamped ``time_ns``."""
        return replace(self.entry, stamp_ns=time_ns), ""

    def latest(self) -> tuple[int, str] | None:
        """(0, parent): a static edge constrains no time."""
        return (0, self.entry.parent)

    newest_ns = 0
    oldest_ns = 0

    def __len__(self) -> int:
        return 1

    def clear(self) -> None:
        """Static transforms survive a clear, as in tf2."""


Cache = TimeCache | StaticCache

__all__ = ["DEFAULT_CACHE_TIME_NS", "Cache", "Entry", "StaticCache", "TimeCache", "seconds_text"]
