"""Output: ROS 2's plain text when piped, colour only on a terminal and never with NO_COLOR."""

from __future__ import annotations

import os
import sys

import click


def use_color() -> bool:
    """Whether stdout is a terminal that may get colour."""
    return sys.stdout.isatty() and not os.environ.get("NO_COLOR")


def lines(items: list[str] | tuple[str, ...]) -> None:
    """Print one item per line."""
    if items:
        click.echo("\n".join(items))


def text(block: str) -> None:
    """Print a block of text exactly (no extra newline when it ends with one)."""
    click.echo(block, nl=not block.endswith("\n"))


def warn(message: str) -> None:
    """Print a one-line warning on stderr."""
    click.echo(message, err=True)
