"""What a recording takes: the topics asked for, and one type per topic.

:class:`Selection` holds ``rosl bag record``'s choice of topics — names expanded as ros2 bag
record expands them (``my_data`` is ``/my_data``), the ``--exclude`` pattern, hidden topics
or not — checked when it is made, so a bad name or pattern is one line before anything
starts. :class:`OtherTypes` keeps rosbag2's rule for a topic published with two types: the
first type seen is recorded; messages of another type are counted (and warned about once per
type), never written under the recorded type's schema.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rosl.bag.errors import BagError
from rosl.graph.records import is_hidden

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.bus.wire import Delivery
    from rosl.graph.cache import GraphCache

RECORDER_NODE = "rosbag2_recorder"  # the recorder's node name, as rosbag2 calls it


@dataclass(frozen=True, slots=True)
class Selection:
    """The topics a recorder takes (all when ``topics`` is None)."""

    topics: frozenset[str] | None = None
    exclude: re.Pattern[str] | None = None
    include_hidden: bool = False

    @classmethod
    def parse(
        cls, topics: list[str] | None, exclude: str | None, include_hidden: bool = False
    ) -> Selection:
        """A selection from the command line's words.

        Raises:
            BagError: a topic name ROS 2 rejects, or ``exclude`` is not a regular expression.
        """
        names = frozenset(_expand(name) for name in topics) if topics else None
        return cls(names, _pattern(exclude), include_hidden)

    def excluded(self, name: str) -> bool:
        """Whether ``--exclude`` matches ``name``."""
        return self.exclude is not None and self.exclude.search(name) is not None

    def wanted(self, name: str) -> bool:
        """Whether a topic is recorded: named (or all), not excluded, not hidden (unless asked)."""
        if self.topics is not None and name not in self.topics:
            return False
        return not self.excluded(name) and (self.include_hidden or not is_hidden(name))


def _expand(name: str) -> str:
    from rosl.node.errors import InvalidNameError
    from rosl.node.names import expand

    try:
        return expand(name, RECORDER_NODE, "/")
    except InvalidNameError as err:
        raise BagError(f"cannot record topic '{name}': {err}") from None


def _pattern(exclude: str | None) -> re.Pattern[str] | None:
    if not exclude:
        return None
    try:
        return re.compile(exclude)
    except re.error as err:
        raise BagError(f"--exclude: not a valid regular expression: '{exclude}' ({err})") from None


@dataclass(slots=True)
class OtherTypes:
    """Messages left out because their topic is recorded with another type."""

    log: Callable[[str], None]
    counts: dict[tuple[str, str], int] = field(default_factory=dict)  # (topic, type) -> count

    def left_out(
        self, name: str, recorded: str, type_name: str, publisher: Callable[[], str]
    ) -> bool:
        """Whether a message of ``type_name`` on ``name`` (recorded as ``recorded``) is left out.

        A left-out message is counted; the first of each such type is warned about in one line
        naming the topic, both types and ``publisher()`` (who sent it).
        """
        if type_name == recorded:
            return False
        key = (name, type_name)
        if key not in self.counts:
            self.counts[key] = 0
            self.log(
                f"[WARN] [rosl_recorder]: topic '{name}' is recorded as {recorded}; "
                f"{publisher()} publishes it as {type_name}: those messages are counted, "
                f"not recorded"
            )
        self.counts[key] += 1
        return True

    def note(self) -> str:
        """The stop summary's note (empty when nothing was left out)."""
        if not self.counts:
            return ""
        parts = ", ".join(
            f"{count} on {name} as {type_name}"
            for (name, type_name), count in sorted(self.counts.items())
        )
        return f", {sum(self.counts.values())} of a second type not recorded ({parts})"


def sender_name(graph: GraphCache, delivery: Delivery, name: str) -> str:
    """The node that sent ``delivery`` on topic ``name``, as the graph shows it."""
    found = graph.sender(delivery.sender, delivery.endpoint, name=name)
    return f"node '{found[0].fqn}'" if found else f"process {delivery.sender:#x}"
