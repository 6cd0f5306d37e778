"""tf2_ros's ``Buffer``: the frame tree plus waiting for transforms, blocking or async.

Waits are driven by what arrives, never by a sleep loop: a ``TransformListener`` feeding the
buffer is drained while a blocking call waits, so ``lookup_transform(..., timeout=...)``
works even inside a callback of a single-threaded executor (in rclpy it blocks that
executor and times out). ``wait_for_transform_async`` futures complete as soon as the data
that makes the transform possible is stored.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any, Protocol

from rosl.node.task import Future
from rosl.tf2.core import BufferCore
from rosl.tf2.interface import BufferInterface
from rosl.tf2.messages import NS, to_ns

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.node import Node
    from rosl.node.participant import Participant


JUMP_BACK_NS = 1_000_000_000


class Feed(Protocol):
    """What feeds a buffer (a TransformListener): its queued data on demand, and its bus."""

    participant: Participant | None

    def drain(self) -> None:
        """Store every transform received but not yet handed to the buffer."""

    def stopped(self) -> bool:
        """Whether its node's context was shut down (a wait then ends at once)."""


def timeout_ns(timeout: Any) -> int:
    """A Duration (rclpy or message), a number of seconds, or None (no wait), in ns."""
    if timeout is None:
        return 0
    if isinstance(timeout, (int, float)):
        return round(timeout * NS)
    return to_ns(timeout, "duration")


class Buffer(BufferCore, BufferInterface):
    """Stores transforms and answers lookups, waiting for them when asked (tf2_ros.Buffer)."""

    def __init__(self, cache_time: Any = None, node: Node | None = None) -> None:
        BufferCore.__init__(self, cache_time)
        BufferInterface.__init__(self)
        self._new_data_callbacks: list[Callable[[], None]] = []
        self._callbacks_lock = threading.RLock()
        self._feeds: list[Feed] = []
        self._changed = threading.Condition()
        self._waiters = 0
        self._last_now_ns = 0
        from rosl.node.clock import Clock

        self.clock = Clock() if node is None else node.get_clock()
        if node is not None:
            from rosl.idl.registry import get_service_class

            frame_graph = get_service_class("tf2_msgs/srv/FrameGraph")
            self.srv = node.create_service(frame_graph, "tf2_frames", self._frames)

    def _frames(self, request: Any, response: Any) -> Any:
        del request
        response.frame_yaml = self.all_frames_as_yaml()
        return response

    # --- new data ----------------------------------------------------------------------------

    def attach(self, feed: Feed) -> None:
        """Let blocking waits drain ``feed`` (a listener calls this)."""
        self._feeds.append(feed)

    def detach(self, feed: Feed) -> None:
        """Stop draining ``feed``."""
        if feed in self._feeds:
            self._feeds.remove(feed)

    def set_transform(self, transform: Any, authority: str) -> None:
        """Store a dynamic transform; waiters and async waits look again."""
        self._check_time_jump()
        super().set_transform(transform, authority)
        self._new_data()

    def _check_time_jump(self) -> None:
        """Clear the buffer when the clock went back by more than 1 s (a bag looping).

        tf2_ros does this from a clock jump callback; here it is looked at as data comes.
        """
        now = self.clock.now_ns()
        if now + JUMP_BACK_NS < self._last_now_ns:
            self._log.warning("Detected jump back in time. Clearing tf buffer.")
            self.clear()
        self._last_now_ns = now

    def set_transform_static(self, transform: Any, authority: str) -> None:
        """Store a static transform; waiters and async waits look again."""
        super().set_transform_static(transform, authority)
        self._new_data()

    def _new_data(self) -> None:
        with self._callbacks_lock:
            for callback in list(self._new_data_callbacks):
                callback()
        if self._waiters:
            with self._changed:
                self._changed.notify_all()
            for feed in list(self._feeds):
                if feed.participant is not None:
                    feed.participant.notify()

    def _wait(self, ready: Callable[[], bool], timeout: Any) -> bool:
        """Block until ``ready()`` (looked at after each new transform) or the timeout."""
        seconds = timeout_ns(timeout) / NS
        if seconds <= 0 or ready():
            return ready()
        feeds = list(self._feeds)
        participant = next((f.participant for f in feeds if f.participant is not None), None)

        def fed() -> bool:
            for feed in feeds:
                feed.drain()
            return ready() or any(feed.stopped() for feed in feeds)

        with self._changed:
            self._waiters += 1
        try:
            if participant is not None:
                participant.wait(fed, seconds)
                return ready()
            with self._changed:
                return self._changed.wait_for(ready, seconds)
        finally:
            with self._changed:
                self._waiters -= 1

    # --- blocking ----------------------------------------------------------------------------

    def lookup_transform(
        self, target_frame: str, source_frame: str, time: Any, timeout: Any = None
    ) -> Any:
        """target←source at ``time`` (0: latest), waiting up to ``timeout`` for it.

        Raises:
            TransformException: still not possible when the timeout ends (tf2's reason).
        """
        self.can_transform(target_frame, source_frame, time, timeout)
        return self.lookup_transform_core(target_frame, source_frame, time)

    def lookup_transform_full(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any,
        fixed_frame: str, timeout: Any = None,
    ) -> Any:  # fmt: skip
        """target(target_time)←source(source_time) through ``fixed_frame``, waiting."""
        self.can_transform_full(
            target_frame, target_time, source_frame, source_time, fixed_frame, timeout
        )
        return self.lookup_transform_full_core(
            target_frame, target_time, source_frame, source_time, fixed_frame
        )

    def can_transform(
        self, target_frame: str, source_frame: str, time: Any, timeout: Any = None,
        return_debug_tuple: bool = False,
    ) -> Any:  # fmt: skip
        """Whether target←source is possible, waiting up to ``timeout`` for it to become so."""
        self._wait(lambda: self.can_transform_core(target_frame, source_frame, time)[0], timeout)
        result = self.can_transform_core(target_frame, source_frame, time)
        return result if return_debug_tuple else result[0]

    def can_transform_full(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any,
        fixed_frame: str, timeout: Any = None, return_debug_tuple: bool = False,
    ) -> Any:  # fmt: skip
        """As :meth:`can_transform`, between two times through ``fixed_frame``."""
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        self._wait(lambda: self.can_transform_full_core(*args)[0], timeout)
        result = self.can_transform_full_core(*args)
        return result if return_debug_tuple else result[0]

    # --- async -------------------------------------------------------------------------------

    def wait_for_transform_async(
        self, target_frame: str, source_frame: str, time: Any
    ) -> Future[Any]:
        """A future that completes with the transform as soon as it is possible."""
        return self._when(
            lambda: self.can_transform_core(target_frame, source_frame, time)[0],
            lambda: self.lookup_transform_core(target_frame, source_frame, time),
        )

    def wait_for_transform_full_async(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any,
        fixed_frame: str,
    ) -> Future[Any]:  # fmt: skip
        """As :meth:`wait_for_transform_async`, between two times through ``fixed_frame``."""
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        return self._when(
            lambda: self.can_transform_full_core(*args)[0],
            lambda: self.lookup_transform_full_core(*args),
        )

    def _when(self, possible: Callable[[], bool], lookup: Callable[[], Any]) -> Future[Any]:
        future: Future[Any] = Future()
        if possible():
            future.set_result(lookup())
            return future

        def on_new_data() -> None:
            if future.done():
                return
            try:
                if possible():
                    future.set_result(lookup())
            except Exception as err:
                future.set_exception(err)

        with self._callbacks_lock:
            self._new_data_callbacks.append(on_new_data)
        future.add_done_callback(lambda _: self._remove_callback(on_new_data))
        return future

    def _remove_callback(self, callback: Callable[[], None]) -> None:
        with self._callbacks_lock:
            if callback in self._new_data_callbacks:
                self._new_data_callbacks.remove(callback)

    async def lookup_transform_async(self, target_frame: str, source_frame: str, time: Any) -> Any:
        """Await the transform target←source at ``time``."""
        await self.wait_for_transform_async(target_frame, source_frame, time)
        return self.lookup_transform_core(target_frame, source_frame, time)

    async def lookup_transform_full_async(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any,
        fixed_frame: str,
    ) -> Any:  # fmt: skip
        """Await the transform target(target_time)←source(source_time)."""
        args = (target_frame, target_time, source_frame, source_time, fixed_frame)
        await self.wait_for_transform_full_async(*args)
        return self.lookup_transform_full_core(*args)


__all__ = ["Buffer", "Feed", "timeout_ns"]
