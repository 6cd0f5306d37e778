"""One clear error for a ``launch``/``launch_ros`` name rosl does not provide."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from collections.abc import Callable


def unsupported_names(module: str, supported: list[str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` raising a LaunchError that names the missing name."""

    def __getattr__(name: str) -> Any:  # noqa: N807 - a module __getattr__
        if name.startswith("__"):
            raise AttributeError(name)
        from rosl.idl.names import did_you_mean
        from rosl.launch.errors import LaunchError

        offered = ", ".join(supported) or "nothing"
        raise LaunchError(
            f"'{module}.{name}' is not supported by rosl{did_you_mean(name, supported)} "
            f"(it provides: {offered})"
        )

    return __getattr__
