"""ROS 2 commands rosl does not have: each answers in one line and exits 1.

``rosl component`` loads C++ components into a container, which pure Python cannot.
"""

from __future__ import annotations

import click

from rosl.errors import RoslError

WHY_NOT = {
    "component": "components are not in rosl: they are C++ libraries a container process loads",
}


class NotThereError(RoslError):
    """A ROS 2 command rosl does not have."""


def _planned(name: str) -> click.Command:
    @click.command(
        name,
        context_settings={"ignore_unknown_options": True, "allow_extra_args": True},
        help=f"Various {name} related sub-commands: {WHY_NOT[name]}.",
    )
    @click.argument("words", nargs=-1, type=click.UNPROCESSED)
    def planned(words: tuple[str, ...]) -> None:
        said = " ".join(("rosl", name, *words[:1]))
        raise NotThereError(f"{said}: {WHY_NOT[name]}")

    return planned


component = _planned("component")
