"""Loggers with ROS 2's console format, levels, throttling, and /rosout.

Lines look like rcutils' default ``[INFO] [1746191204.354415605] [talker]: message`` (format
from ``RCUTILS_CONSOLE_OUTPUT_FORMAT``), go to stderr (stdout with
``RCUTILS_LOGGING_USE_STDOUT=1``), coloured only on a terminal and never with ``NO_COLOR``.
A node's logger also publishes each record on ``/rosout``.
"""

from __future__ import annotations

import contextlib
import enum
import inspect
import os
import sys
import threading
import time
from collections.abc import Callable
from typing import Any


class LoggingSeverity(enum.IntEnum):
    """Log levels (rclpy.logging.LoggingSeverity)."""

    UNSET = 0
    DEBUG = 10
    INFO = 20
    WARN = 30
    ERROR = 40
    FATAL = 50


_COLORS = {
    LoggingSeverity.DEBUG: "\033[32m",
    LoggingSeverity.WARN: "\033[33m",
    LoggingSeverity.ERROR: "\033[31m",
    LoggingSeverity.FATAL: "\033[31m",
}
_levels: dict[str, LoggingSeverity] = {}
_default_level = LoggingSeverity.INFO
_console = True  # --disable-stdout-logs turns console output off (/rosout still gets records)
_lock = threading.Lock()
Sink = Callable[[LoggingSeverity, str, str, str, str, int], None]


def parse_severity(level: str | int | LoggingSeverity) -> LoggingSeverity:
    """Accept 'info', 'INFO', 20 or LoggingSeverity.INFO."""
    if isinstance(level, str):
        word = level.strip().upper()
        return LoggingSeverity["WARN" if word == "WARNING" else word]
    return LoggingSeverity(level)


def set_default_level(level: str | int | LoggingSeverity) -> None:
    """Set the level of every logger without a level of its own (``--log-level info``)."""
    global _default_level
    _default_level = parse_severity(level)


def set_logger_level(name: str, level: str | int | LoggingSeverity) -> None:
    """Set one logger's level (``--log-level talker:=debug``)."""
    _levels[name] = parse_severity(level)


def set_console_output(enabled: bool) -> None:
    """Turn printing of log lines on or off (``--disable-stdout-logs``)."""
    global _console
    _console = enabled


def effective_level(name: str) -> LoggingSeverity:
    """The level applying to ``name`` (its own, its nearest ancestor's, or the default)."""
    parts = name.split(".")
    for end in range(len(parts), 0, -1):
        level = _levels.get(".".join(parts[:end]))
        if level is not None and level is not LoggingSeverity.UNSET:
            return level
    return _default_level


def _use_color(stream: Any) -> bool:
    setting = os.environ.get("RCUTILS_COLORIZED_OUTPUT")
    if os.environ.get("NO_COLOR"):
        return False
    if setting is not None:
        return setting == "1"
    return bool(getattr(stream, "isatty", lambda: False)())


def format_line(severity: LoggingSeverity, name: str, message: str, stamp_ns: int) -> str:
    """Render one record with the console format."""
    template = os.environ.get(
        "RCUTILS_CONSOLE_OUTPUT_FORMAT", "[{severity}] [{time}] [{name}]: {message}"
    )
    seconds, nanos = divmod(stamp_ns, 1_000_000_000)
    return (
        template.replace("{severity}", severity.name)
        .replace("{time}", f"{seconds}.{nanos:09d}")
        .replace("{name}", name)
        .replace("{message}", message)
    )


class Logger:
    """A named logger (rclpy's RcutilsLogger)."""

    def __init__(self, name: str, sink: Sink | None = None) -> None:
        self.name = name
        self._sink = sink
        self._once: set[tuple[str, int]] = set()
        self._throttle: dict[tuple[str, int], float] = {}
        self._skipped: set[tuple[str, int]] = set()

    def get_child(self, name: str) -> Logger:
        """A logger named ``<this>.<name>`` sharing the /rosout sink."""
        return Logger(f"{self.name}.{name}" if self.name else name, self._sink)

    def set_level(self, level: str | int | LoggingSeverity) -> None:
        """Set this logger's level."""
        set_logger_level(self.name, level)

    def get_effective_level(self) -> LoggingSeverity:
        """The level in force for this logger."""
        return effective_level(self.name)

    def is_enabled_for(self, severity: str | int | LoggingSeverity) -> bool:
        """Whether a record of ``severity`` would be printed."""
        return parse_severity(severity) >= self.get_effective_level()

    def log(self, message: Any, severity: str | int | LoggingSeverity, **options: Any) -> bool:
        """Log ``message``; options ``once``, ``skip_first``, ``throttle_duration_sec``."""
        level = parse_severity(severity)
        if level < effective_level(self.name):
            return False
        caller = inspect.stack(context=0)[2] if options else None
        site = (caller.filename, caller.lineno) if caller else ("", 0)
        if options.get("once"):
            if site in self._once:
                return False
            self._once.add(site)
        if options.get("skip_first") and site not in self._skipped:
            self._skipped.add(site)
            return False
        period = options.get("throttle_duration_sec")
        if period:
            now = time.monotonic()
            if now - self._throttle.get(site, -1e18) < float(period):
                return False
            self._throttle[site] = now
        self._emit(level, str(message))
        return True

    def _emit(self, level: LoggingSeverity, message: str) -> None:
        stamp = time.time_ns()
        stream = sys.stdout if os.environ.get("RCUTILS_LOGGING_USE_STDOUT") == "1" else sys.stderr
        line = format_line(level, self.name, message, stamp)
        if _use_color(stream) and level in _COLORS:
            line = f"{_COLORS[level]}{line}\033[0m"
        if _console:
            with _lock:
                try:
                    stream.write(line + "\n")
                    stream.flush()
                except (OSError, ValueError):
                    pass
        if self._sink is not None:
            frame = inspect.stack(context=0)[3] if len(inspect.stack(context=0)) > 3 else None
            where = (frame.filename, frame.function, frame.lineno) if frame else ("", "", 0)
            with contextlib.suppress(Exception):
                self._sink(level, self.name, message, *where)

    def debug(self, message: Any, **options: Any) -> bool:
        """Log at DEBUG."""
        return self.log(message, LoggingSeverity.DEBUG, **options)

    def info(self, message: Any, **options: Any) -> bool:
        """Log at INFO."""
        return self.log(message, LoggingSeverity.INFO, **options)

    def warning(self, message: Any, **options: Any) -> bool:
        """Log at WARN."""
        return self.log(message, LoggingSeverity.WARN, **options)

    warn = warning

    def error(self, message: Any, **options: Any) -> bool:
        """Log at ERROR."""
        return self.log(message, LoggingSeverity.ERROR, **options)

    def fatal(self, message: Any, **options: Any) -> bool:
        """Log at FATAL."""
        return self.log(message, LoggingSeverity.FATAL, **options)


def get_logger(name: str) -> Logger:
    """A logger without /rosout (rclpy.logging.get_logger)."""
    return Logger(name)
