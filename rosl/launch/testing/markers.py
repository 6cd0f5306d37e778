"""launch_testing.markers: ``keep_alive`` and ``retry_on_failure``."""

from __future__ import annotations

import functools
import time
from typing import TYPE_CHECKING, Any, TypeVar

if TYPE_CHECKING:
    import unittest
    from collections.abc import Callable

T = TypeVar("T")


def keep_alive(test_description: T) -> T:
    """Keep the launch up until the active tests end, even after every process has exited.

    Without it the launch ends when its last process does, and active tests still running then
    fail the run ('Processes under test stopped before tests completed').
    """
    markers = getattr(test_description, "__markers__", None)
    if markers is None:
        markers = {}
        test_description.__markers__ = markers  # type: ignore[attr-defined]
    markers["keep_alive"] = True
    return test_description


def retry_on_failure(
    *, times: int, delay: float | None = None
) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Run a test method up to ``times`` times while it fails with an AssertionError.

    ``delay``: seconds to wait before each retry.
    """
    if times < 1:
        raise ValueError("retry_on_failure(times=...) needs at least 1")

    def decorate(function: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(function)
        def wrapper(self: unittest.TestCase, *args: Any, **kwargs: Any) -> Any:
            for _ in range(times - 1):
                try:
                    return function(self, *args, **kwargs)
                except AssertionError:
                    if delay:
                        time.sleep(delay)
            return function(self, *args, **kwargs)

        return wrapper

    return decorate


__all__ = ["keep_alive", "retry_on_failure"]
