"""ROS 2 commands rosl does not have yet: each answers in one line and exits 1.

``rosl lifecycle`` comes with lifecycle nodes in a later version; ``rosl component`` loads C++
components into a container, which pure Python cannot.
"""

from __future__ import annotations

import click

from rosl.errors import RoslError

LATER = "{what} are not in rosl yet; they come in a later version"
WHY_NOT = {
    "lifecycle": LATER.format(what="lifecycle nodes"),
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


lifecycle = _planned("lifecycle")
component = _planned("component")
