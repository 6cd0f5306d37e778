"""The frame tree: one cache per child frame, and tf2's walks through it.

``lookup`` walks up from the source frame and from the target frame to where the two walks
meet, composing each edge at the asked time (time 0: the latest time every edge on the way
has data for). Errors carry tf2's own messages, so code that prints them reads the same.
Plain nanoseconds and :class:`~rosl.tf2.transform.Transform` here; messages are
:mod:`rosl.tf2.core`'s business. Thread-safe: one lock around every read and write.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

from rosl.tf2.cache import DEFAULT_CACHE_TIME_NS, Entry, StaticCache, TimeCache, seconds_text
from rosl.tf2.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
)
from rosl.tf2.transform import Transform

if TYPE_CHECKING:
    from rosl.tf2.cache import Cache

MAX_GRAPH_DEPTH = 1000


class FrameTree:
    """Frames, each with the cache of its edge to its parent (tf2's BufferCore, in ns)."""

    def __init__(self, cache_time_ns: int = DEFAULT_CACHE_TIME_NS) -> None:
        self.cache_time_ns = cache_time_ns
        self.caches: dict[str, Cache] = {}  # by child frame
        self.known: dict[str, None] = {}  # every frame named, in the order first seen
        self.authority: dict[str, str] = {}  # child frame -> who sent its latest transform
        self.lock = threading.RLock()

    # --- writing -----------------------------------------------------------------------------

    def insert(
        self, parent: str, child: str, stamp_ns: int, transform: Transform, authority: str,
        static: bool,
    ) -> bool:  # fmt: skip
        """Store parent←child; False when it is older than the edge's cache keeps."""
        entry = Entry(stamp_ns, parent, transform)
        with self.lock:
            self.known.setdefault(child)
            self.known.setdefault(parent)
            cache = self.caches.get(child)
            if cache is None or cache.static != static:
                cache = StaticCache(entry) if static else TimeCache(self.cache_time_ns)
                self.caches[child] = cache
            if not cache.insert(entry):
                return False
            self.authority[child] = authority
        return True

    def clear(self) -> None:
        """Forget the dynamic transforms (frames and static transforms stay)."""
        with self.lock:
            for cache in self.caches.values():
                cache.clear()

    # --- frames ------------------------------------------------------------------------------

    def validate(self, frame: str, where: str) -> str:
        """Raise tf2's exception for a frame id that cannot be looked up.

        Raises:
            InvalidArgumentException: empty, or starting with '/'.
            LookupException: not known.
        """
        if problem := _invalid(frame):
            raise InvalidArgumentException(
                f'Invalid argument "{frame}" passed to {where} - {problem}'
            )
        if frame not in self.known:
            raise LookupException(f'"{frame}" passed to {where} does not exist. ')
        return frame

    def check(self, frame: str, where: str) -> str:
        """tf2's message for a frame ``canTransform`` refuses, or ''."""
        problem = _invalid(frame) or ("" if frame in self.known else "frame does not exist")
        return f'Invalid frame ID "{frame}" passed to {where} - {problem}' if problem else ""

    def parent(self, child: str) -> str | None:
        """The parent of ``child`` in its latest transform (None for a root)."""
        with self.lock:
            cache = self.caches.get(child)
            latest = cache.latest() if cache is not None else None
        return latest[1] if latest else None

    # --- lookups -----------------------------------------------------------------------------

    def lookup(self, target: str, source: str, time_ns: int) -> tuple[Transform, int]:
        """target←source at ``time_ns`` (0: latest common time) and the time used.

        Raises:
            TransformException: a bad or unknown frame, frames not connected, extrapolation.
        """
        with self.lock:
            if target == source:
                cache = self.caches.get(target)
                return Transform(), (cache.newest_ns if cache and time_ns == 0 else time_ns)
            self.validate(target, "lookupTransform argument target_frame")
            self.validate(source, "lookupTransform argument source_frame")
            if time_ns == 0:
                time_ns = self.latest_common_time(target, source)
            return self._walk(target, source, time_ns), time_ns

    def possible(self, target: str, source: str, time_ns: int) -> tuple[bool, str]:
        """Whether ``lookup`` would succeed, and tf2's message when not."""
        if target == source:
            return True, ""
        for frame, where in ((target, "target_frame"), (source, "source_frame")):
            if message := self.check(frame, f"canTransform argument {where}"):
                return False, message
        try:
            self.lookup(target, source, time_ns)
        except (ConnectivityException, ExtrapolationException, LookupException) as err:
            return False, str(err)
        return True, ""

    def _walk(self, target: str, source: str, time_ns: int) -> Transform:
        """target←source at ``time_ns`` through the frames both walks up the tree reach."""
        suffix = f", when looking up transform from frame [{source}] to frame [{target}]"
        up: dict[str, Transform] = {source: Transform()}  # frame <- source
        frame, to_source, source_error = source, Transform(), None
        while (cache := self.caches.get(frame)) is not None:
            entry, error = cache.at(time_ns)
            if entry is None:
                source_error = error
                break
            to_source = entry.transform * to_source
            frame = entry.parent
            if frame in up:
                raise LookupException(self._loop_text())
            up[frame] = to_source
            if frame == target:
                return to_source
        frame, to_target = target, Transform()  # frame <- target
        for _ in range(MAX_GRAPH_DEPTH + 1):
            if frame in up:
                return to_target.inverse() * up[frame]
            cache = self.caches.get(frame)
            if cache is None:
                break
            entry, error = cache.at(time_ns)
            if entry is None:
                raise ExtrapolationException(error + suffix)
            to_target = entry.transform * to_target
            frame = entry.parent
        else:
            raise LookupException(self._loop_text())
        if source_error is not None:
            raise ExtrapolationException(source_error + suffix)
        raise ConnectivityException(_not_connected(target, source))

    def latest_common_time(self, target: str, source: str) -> int:
        """The newest time every dynamic edge between the frames has data for (0: all static).

        Raises:
            ConnectivityException: the frames are in separate trees.
            LookupException: the tree has a loop.
        """
        with self.lock:
            if target == source:
                cache = self.caches.get(source)
                return cache.newest_ns if cache is not None else 0
            up = self._latest_path(source, stop=target)
            parents = [parent for _, parent in up]
            if target in parents:
                return _min_stamp(up[: parents.index(target) + 1])
            down = self._latest_path(target, stop=source)
            for index, (_, parent) in enumerate(down):
                if parent == source:
                    return _min_stamp(down[: index + 1])
                if parent in parents:
                    return _min_stamp(down[: index + 1] + up[: parents.index(parent) + 1])
            raise ConnectivityException(_not_connected(target, source))

    def _latest_path(self, frame: str, stop: str) -> list[tuple[int, str]]:
        """(latest stamp, parent) up from ``frame`` to its root, or to ``stop``."""
        path: list[tuple[int, str]] = []
        while (cache := self.caches.get(frame)) is not None and (latest := cache.latest()):
            path.append(latest)
            frame = latest[1]
            if frame == stop:
                break
            if len(path) > MAX_GRAPH_DEPTH:
                raise LookupException(self._loop_text())
        return path

    def chain(self, target: str, source: str) -> list[str]:
        """The frames from ``source`` to ``target`` along the tree, both ends included."""
        with self.lock:
            up = [source]
            while (parent := self.parent(up[-1])) is not None and parent not in up:
                up.append(parent)
            down = [target]
            while down[-1] not in up and (parent := self.parent(down[-1])) is not None:
                if parent in down:
                    break
                down.append(parent)
            if down[-1] not in up:
                raise ConnectivityException(_not_connected(target, source))
            return up[: up.index(down[-1])] + down[::-1]

    # --- texts -------------------------------------------------------------------------------

    def frames_text(self) -> str:
        """tf2's allFramesAsString: 'Frame X exists with parent Y.' per child frame."""
        with self.lock:
            return "".join(
                f"Frame {child} exists with parent {(cache.latest() or (0, 'NO_PARENT'))[1]}.\n"
                for child, cache in self.caches.items()
            )

    def frames_yaml(self) -> str:
        """tf2's allFramesAsYAML: parent, broadcaster, rate and stamps per child frame."""
        with self.lock:
            out = []
            for child, cache in self.caches.items():
                latest = cache.latest()
                if latest is None:
                    continue
                span = cache.newest_ns - cache.oldest_ns
                rate = len(cache) * 1e9 / max(span, 100_000)
                out.append(
                    f"{child}: \n  parent: '{latest[1]}'\n"
                    f"  broadcaster: '{self.authority.get(child, 'no recorded authority')}'\n"
                    f"  rate: {rate:.3f}\n"
                    f"  most_recent_transform: {seconds_text(cache.newest_ns)}\n"
                    f"  oldest_transform: {seconds_text(cache.oldest_ns)}\n"
                    f"  buffer_length: {span / 1e9:.3f}\n"
                )
            return "".join(out) or "[]"

    def _loop_text(self) -> str:
        return f"The tf tree is invalid because it contains a loop.\n{self.frames_text()}\n"


def _invalid(frame: str) -> str:
    if not frame:
        return "in tf2 frame_ids cannot be empty"
    if frame.startswith("/"):
        return "in tf2 frame_ids cannot start with a '/'"
    return ""


def _min_stamp(path: list[tuple[int, str]]) -> int:
    return min((stamp for stamp, _ in path if stamp), default=0)


def _not_connected(target: str, source: str) -> str:
    return (
        f"Could not find a connection between '{target}' and '{source}' because they are not "
        "part of the same tree.Tf has two or more unconnected trees."
    )


__all__ = ["MAX_GRAPH_DEPTH", "FrameTree"]
