"""Timers and rates on a node's clock (wall time, or sim time when ``use_sim_time``)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rosl.node.clock import NS, Duration

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.clock import Clock


class Timer:
    """Calls ``callback`` every ``timer_period_ns`` on ``clock`` (rclpy.timer.Timer)."""

    def __init__(self, callback: Callable[[], Any] | None, period_ns: int, clock: Clock) -> None:
        if period_ns <= 0:
            raise ValueError("a timer period must be greater than 0")
        self.callback = callback
        self.clock = clock
        self._period_ns = int(period_ns)
        self._canceled = False
        self._last_call_ns = clock.now_ns()
        self._next_call_ns = self._last_call_ns + self._period_ns
        self.destroyed = False

    @property
    def timer_period_ns(self) -> int:
        """The period; setting it reschedules the next call from the last one."""
        return self._period_ns

    @timer_period_ns.setter
    def timer_period_ns(self, period_ns: int) -> None:
        if period_ns <= 0:
            raise ValueError("a timer period must be greater than 0")
        self._period_ns = int(period_ns)
        self._next_call_ns = self._last_call_ns + self._period_ns

    def change_period(self, period_sec: float) -> None:
        """Set the period in seconds."""
        self.timer_period_ns = round(period_sec * NS)

    def cancel(self) -> None:
        """Stop calling back until :meth:`reset`."""
        self._canceled = True

    def reset(self) -> None:
        """Restart: the next call is one period from now."""
        self._canceled = False
        self._last_call_ns = self.clock.now_ns()
        self._next_call_ns = self._last_call_ns + self._period_ns

    def is_canceled(self) -> bool:
        """Whether the timer is canceled."""
        return self._canceled

    def is_ready(self) -> bool:
        """Whether a call is due."""
        return not self._canceled and self.clock.now_ns() >= self._next_call_ns

    def time_until_next_call(self) -> int | None:
        """Nanoseconds until the next call (None when canceled)."""
        if self._canceled:
            return None
        return self._next_call_ns - self.clock.now_ns()

    def time_since_last_call(self) -> int:
        """Nanoseconds since the last call."""
        return self.clock.now_ns() - self._last_call_ns

    def call(self) -> None:
        """Mark the call done and run the callback (missed periods are skipped, as in rcl)."""
        now = self.clock.now_ns()
        self._last_call_ns = now
        self._next_call_ns += self._period_ns
        if self._next_call_ns <= now:
            behind = (now - self._next_call_ns) // self._period_ns + 1
            self._next_call_ns += behind * self._period_ns
        if self.callback is not None:
            self.callback()

    def destroy(self) -> None:
        """Stop for good."""
        self._canceled = True
        self.destroyed = True


class Rate:
    """Sleeps to keep a loop at a frequency (rclpy.timer.Rate)."""

    def __init__(self, frequency: float, clock: Clock) -> None:
        if frequency <= 0:
            raise ValueError("a rate's frequency must be greater than 0")
        self._period_ns = int(NS / frequency)
        self._clock = clock
        self._next_ns = clock.now_ns() + self._period_ns

    def sleep(self) -> None:
        """Sleep until the next period starts."""
        now = self._clock.now_ns()
        if self._next_ns > now:
            self._clock.sleep_for(Duration(nanoseconds=self._next_ns - now))
            self._next_ns += self._period_ns
        else:
            self._next_ns = now + self._period_ns

    def destroy(self) -> None:
        """Nothing to release."""
