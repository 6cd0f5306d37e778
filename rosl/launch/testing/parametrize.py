"""launch_testing.parametrize: run one launch test file once per set of values.

::

    @launch_testing.parametrize("rate, topic", [(1.0, "a"), (2.0, "b")])
    def generate_test_description(rate, topic): ...

Each run gets its values as arguments of ``generate_test_description`` and, by name, of the
test methods; its results are named ``name[rate=1.0, topic=a]``.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator


def parametrize(
    argnames: str, argvalues: list[Any]
) -> Callable[[Callable[..., Any]], Callable[[], Iterator[tuple[Any, dict[str, Any]]]]]:
    """Decorate ``generate_test_description`` to run once per entry of ``argvalues``.

    Args:
        argnames: the argument names, separated by commas (as pytest.mark.parametrize).
        argvalues: one value (or a tuple of values, one per name) per run.
    """
    names = [name.strip() for name in argnames.split(",") if name.strip()]
    values = [value if isinstance(value, tuple) else (value,) for value in argvalues]

    def decorate(function: Callable[..., Any]) -> Any:
        @functools.wraps(function)
        def runs() -> Iterator[tuple[Any, dict[str, Any]]]:
            for value in values:
                arguments = dict(zip(names, value, strict=False))
                bound = functools.partial(function, **arguments)
                functools.update_wrapper(bound, function)
                yield bound, arguments

        runs.__parametrized__ = True  # type: ignore[attr-defined]
        return runs

    return decorate


__all__ = ["parametrize"]
