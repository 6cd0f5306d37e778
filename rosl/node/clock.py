"""Time, Duration and Clock as in rclpy, with sim time that follows ``/clock``.

Integer nanoseconds throughout. A node with ``use_sim_time`` true gets a ROS-time clock whose
``now()`` is the last ``/clock`` value received (0 before the first), and its timers advance
with it.
"""

from __future__ import annotations

import enum
import threading
import time as _time
from functools import total_ordering
from typing import Any

NS = 1_000_000_000


class ClockType(enum.IntEnum):
    """Which clock a time belongs to (rclpy.clock.ClockType)."""

    UNINITIALIZED = 0
    ROS_TIME = 1
    SYSTEM_TIME = 2
    STEADY_TIME = 3


@total_ordering
class Duration:
    """A span of time in integer nanoseconds (rclpy.duration.Duration)."""

    __slots__ = ("_ns",)

    def __init__(self, *, seconds: float = 0, nanoseconds: int = 0) -> None:
        self._ns = round(seconds * NS) + int(nanoseconds)

    @property
    def nanoseconds(self) -> int:
        """The span in nanoseconds."""
        return self._ns

    def to_msg(self) -> Any:
        """Return a builtin_interfaces/msg/Duration."""
        from rosl.idl.registry import get_message_class

        sec, nanosec = divmod(self._ns, NS)
        return get_message_class("builtin_interfaces/msg/Duration")(sec=sec, nanosec=nanosec)

    @classmethod
    def from_msg(cls, msg: Any) -> Duration:
        """Build from a builtin_interfaces/msg/Duration."""
        return cls(seconds=msg.sec, nanoseconds=msg.nanosec)

    @classmethod
    def max(cls) -> Duration:
        """The largest duration (ROS's 'infinite')."""
        return cls(nanoseconds=2**63 - 1)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Duration) and self._ns == other._ns

    def __lt__(self, other: Duration) -> bool:
        if not isinstance(other, Duration):
            return NotImplemented
        return self._ns < other._ns

    def __hash__(self) -> int:
        return hash(self._ns)

    def __add__(self, other: Duration) -> Duration:
        if not isinstance(other, Duration):
            return NotImplemented  # Duration + Time is Time.__radd__
        return Duration(nanoseconds=self._ns + other._ns)

    def __sub__(self, other: Duration) -> Duration:
        return Duration(nanoseconds=self._ns - other._ns)

    def __mul__(self, factor: float) -> Duration:
        return Duration(nanoseconds=int(self._ns * factor))

    def __repr__(self) -> str:
        return f"Duration(nanoseconds={self._ns})"


@total_ordering
class Time:
    """A point in time on one clock, in integer nanoseconds (rclpy.time.Time)."""

    __slots__ = ("_clock_type", "_ns")

    def __init__(
        self,
        *,
        seconds: float = 0,
        nanoseconds: int = 0,
        clock_type: ClockType = ClockType.SYSTEM_TIME,
    ) -> None:
        self._ns = round(seconds * NS) + int(nanoseconds)
        if self._ns < 0:
            raise ValueError("Time must not be negative")
        self._clock_type = clock_type

    @property
    def nanoseconds(self) -> int:
        """Nanoseconds since the clock's epoch."""
        return self._ns

    @property
    def clock_type(self) -> ClockType:
        """The clock this time belongs to."""
        return self._clock_type

    def seconds_nanoseconds(self) -> tuple[int, int]:
        """(seconds, nanoseconds within the second)."""
        return divmod(self._ns, NS)

    def to_msg(self) -> Any:
        """Return a builtin_interfaces/msg/Time."""
        from rosl.idl.registry import get_message_class

        sec, nanosec = divmod(self._ns, NS)
        return get_message_class("builtin_interfaces/msg/Time")(sec=sec, nanosec=nanosec)

    @classmethod
    def from_msg(cls, msg: Any, clock_type: ClockType = ClockType.ROS_TIME) -> Time:
        """Build from a builtin_interfaces/msg/Time."""
        return cls(seconds=msg.sec, nanoseconds=msg.nanosec, clock_type=clock_type)

    def _check(self, other: Time) -> None:
        if other._clock_type != self._clock_type:
            raise TypeError("cannot compare or subtract times of different clock types")

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Time)
            and self._ns == other._ns
            and self._clock_type == other._clock_type
        )

    def __lt__(self, other: Time) -> bool:
        if not isinstance(other, Time):
            return NotImplemented
        self._check(other)
        return self._ns < other._ns

    def __hash__(self) -> int:
        return hash((self._ns, self._clock_type))

    def __add__(self, other: Duration) -> Time:
        if not isinstance(other, Duration):
            return NotImplemented
        return Time(nanoseconds=self._ns + other.nanoseconds, clock_type=self._clock_type)

    __radd__ = __add__

    def __sub__(self, other: Time | Duration) -> Any:
        if isinstance(other, Time):
            self._check(other)
            return Duration(nanoseconds=self._ns - other._ns)
        if isinstance(other, Duration):
            return Time(nanoseconds=self._ns - other.nanoseconds, clock_type=self._clock_type)
        return NotImplemented

    def __repr__(self) -> str:
        return f"Time(nanoseconds={self._ns}, clock_type={self._clock_type.name})"


class Clock:
    """A clock: system, steady, or ROS time (which may follow ``/clock``)."""

    def __init__(self, *, clock_type: ClockType = ClockType.SYSTEM_TIME) -> None:
        self.clock_type = clock_type
        self._sim_ns: int | None = None  # set when ROS time follows /clock
        self._changed = threading.Condition()

    @property
    def ros_time_is_active(self) -> bool:
        """Whether this clock follows /clock (sim time)."""
        return self._sim_ns is not None

    def now_ns(self) -> int:
        """The current time in nanoseconds."""
        if self._sim_ns is not None:
            return self._sim_ns
        if self.clock_type is ClockType.STEADY_TIME:
            return _time.monotonic_ns()
        return _time.time_ns()

    def now(self) -> Time:
        """The current time."""
        return Time(nanoseconds=self.now_ns(), clock_type=self.clock_type)

    def set_sim_time(self, active: bool) -> None:
        """Start (at 0) or stop following /clock."""
        with self._changed:
            self._sim_ns = 0 if active else None
            self._changed.notify_all()

    def set_sim_now(self, nanoseconds: int) -> None:
        """Move sim time (called for each /clock message)."""
        with self._changed:
            if self._sim_ns is not None:
                self._sim_ns = nanoseconds
                self._changed.notify_all()

    def sleep_for(self, duration: Duration | float) -> bool:
        """Sleep on this clock; with sim time, until /clock has advanced far enough."""
        span = duration.nanoseconds if isinstance(duration, Duration) else int(duration * NS)
        return self.sleep_until(Time(nanoseconds=self.now_ns() + span, clock_type=self.clock_type))

    def sleep_until(self, until: Time) -> bool:
        """Sleep until ``until`` on this clock."""
        if self._sim_ns is None:
            remaining = (until.nanoseconds - self.now_ns()) / NS
            if remaining > 0:
                _time.sleep(remaining)
            return True
        with self._changed:
            return self._changed.wait_for(
                lambda: self._sim_ns is None or self._sim_ns >= until.nanoseconds
            )


class ROSClock(Clock):
    """A ROS-time clock (rclpy.clock.ROSClock)."""

    def __init__(self) -> None:
        super().__init__(clock_type=ClockType.ROS_TIME)
