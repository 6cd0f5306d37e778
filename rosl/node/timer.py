"""Timers and rates on a node's clock (wall time, or sim time when ``use_sim_time``)."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from rosl.node.callback_groups import Executable
from rosl.node.clock import NS, Duration
from rosl.node.errors import TimerPeriodError

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.clock import Clock


MAX_PERIOD_NS = 2**63 - 1  # rcl keeps a timer's period in int64 nanoseconds


def seconds_to_period_ns(seconds: float, what: str = "create_timer: timer_period_sec") -> int:
    """Return ``seconds`` as a timer period in integer nanoseconds.

    Raises:
        TimerPeriodError: not a finite number > 0, or too long for int64 nanoseconds.
    """
    try:
        value = float(seconds)
    except (TypeError, ValueError):
        value = math.nan
    if not math.isfinite(value) or value <= 0:
        raise TimerPeriodError(f"{what} must be a finite number > 0, got {seconds!r}")
    if value * NS > MAX_PERIOD_NS:
        raise TimerPeriodError(
            f"{what} must be at most {MAX_PERIOD_NS // NS} s (int64 nanoseconds), got {seconds!r}"
        )
    return max(1, round(value * NS))


def _checked_ns(nanoseconds: int) -> int:
    number = isinstance(nanoseconds, int | float) and not isinstance(nanoseconds, bool)
    if (
        not number
        or (isinstance(nanoseconds, float) and not math.isfinite(nanoseconds))
        or not 0 < nanoseconds <= MAX_PERIOD_NS
    ):
        raise TimerPeriodError(
            f"timer_period_ns must be an integer > 0 and at most {MAX_PERIOD_NS}, "
            f"got {nanoseconds!r}"
        )
    return int(nanoseconds)


class Timer(Executable):
    """Calls ``callback`` every ``timer_period_ns`` on ``clock`` (rclpy.timer.Timer)."""

    _is_timer = True
    _what = "timer"

    def __init__(
        self,
        callback: Callable[[], Any] | None,
        period_ns: int,
        clock: Clock,
        wake: Callable[[], None] | None = None,
    ) -> None:
        self.callback = callback
        self.clock = clock
        self._wake = wake  # tells the spinning executor that the schedule changed
        self._period_ns = _checked_ns(period_ns)
        self._canceled = False
        self._last_call_ns = clock.now_ns()
        self._next_call_ns = self._last_call_ns + self._period_ns
        self.destroyed = False

    @property
    def timer_period_ns(self) -> int:
        """The period; setting it starts the new period at once.

        The next call comes one new period after the change, and the calls after it one new
        period apart. rcl only swaps the period and keeps the call already scheduled (up to
        one old period away); rescheduling from the last call instead made a call due at once,
        or a few milliseconds before the next one. Neither is what a user changing a rate
        expects. Setting the period it already has changes nothing (code that re-applies a
        parameter often must not postpone the timer for ever).
        """
        return self._period_ns

    @timer_period_ns.setter
    def timer_period_ns(self, period_ns: int) -> None:
        checked = _checked_ns(period_ns)
        if checked == self._period_ns:
            return
        self._period_ns = checked
        self._next_call_ns = self.clock.now_ns() + self._period_ns
        self._rescheduled()

    def change_period(self, period_sec: float) -> None:
        """Set the period in seconds.

        Raises:
            TimerPeriodError: not a finite number of seconds > 0.
        """
        self.timer_period_ns = seconds_to_period_ns(period_sec, "change_period: period_sec")

    def cancel(self) -> None:
        """Stop calling back until :meth:`reset`."""
        self._canceled = True

    def reset(self) -> None:
        """Restart: the next call is one period from now (the last call's time is kept)."""
        now = self.clock.now_ns()
        self._canceled = False
        self._next_call_ns = now + self._period_ns
        self._last_call_ns = min(self._last_call_ns, now)  # the clock went back (sim time on)
        self._rescheduled()

    def _rescheduled(self) -> None:
        if self._wake is not None:  # an executor asleep until the old due time wakes up
            self._wake()

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
        self._advance()
        if self.callback is not None:
            self.callback()

    def _ready(self) -> bool:  # is_ready, one call less: executors ask every look
        return not self._canceled and self.clock.now_ns() >= self._next_call_ns

    def _take(self) -> Callable[[], Any] | None:
        if self._canceled or self.destroyed:
            return None
        now = self.clock.now_ns()
        if now < self._next_call_ns:
            return None
        self._advance(now)
        return self.callback

    def _advance(self, now: int | None = None) -> None:
        if now is None:
            now = self.clock.now_ns()
        self._last_call_ns = now
        self._next_call_ns += self._period_ns
        if self._next_call_ns <= now:
            behind = (now - self._next_call_ns) // self._period_ns + 1
            self._next_call_ns += behind * self._period_ns

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
