"""ROS 2's YAML launch format (``*.launch.yaml``), read with line numbers.

::

    launch:
    - arg: {name: topic, default: chatter, description: "..."}
    - node:
        pkg: tutorial_pkg
        exec: my_publisher
        name: publisher_node
        namespace: demo
        output: screen
        param: [{name: rate, value: 2.0}, {from: "$(find-pkg-share p)/params.yaml"}]
        remap: [{from: my_data, to: "$(var topic)"}]
    - include: {file: "$(find-pkg-share p)/launch/other.launch.py", arg: [{name: x, value: "1"}]}

Entries become actions through :mod:`rosl.launch.frontend`, the path XML launch files take
too: the same entries, attributes and ``$(...)`` substitutions. Errors name the file and line.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import yaml

from rosl.launch.errors import LaunchError
from rosl.launch.frontend import Entity, build_description

if TYPE_CHECKING:
    from collections.abc import Hashable
    from pathlib import Path

    from rosl.launch.description import LaunchDescription
    from rosl.launch.frontend import Tag

LINE = "__line__"


class _Loader(yaml.SafeLoader):
    """A safe loader that remembers the line of every mapping."""


def _mapping_with_line(loader: _Loader, node: yaml.MappingNode) -> dict[Hashable, Any]:
    mapping = loader.construct_mapping(node, deep=True)
    mapping[LINE] = node.start_mark.line + 1
    return mapping


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping_with_line)


def _plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items() if k != LINE}
    if isinstance(value, list):
        return [_plain(v) for v in value]
    return value


class YamlEntity(Entity):
    """A YAML mapping (or, for a group, a list of entries) as the frontend reads it."""

    noun = "entry"

    def __init__(self, path: Path, line: int, kind: str, element: Any) -> None:
        super().__init__(path, line, kind)
        self.element = element

    def value(self, name: str) -> Any:
        """The key's value (None when absent)."""
        if not isinstance(self.element, dict):
            return None
        return _plain(self.element.get(name))

    def nested(self, name: str) -> list[Entity]:
        """The mappings listed under ``name`` (one mapping counts as a list of one)."""
        found = self.element.get(name) if isinstance(self.element, dict) else None
        if found is None:
            return []
        items = [found] if isinstance(found, dict) else found
        if not isinstance(items, list) or not all(isinstance(i, dict) for i in items):
            raise self.fail(f"'{name}' of {self.label} must be a list of mappings")
        return [YamlEntity(self.path, item.get(LINE, self.line), name, item) for item in items]

    def actions(self) -> list[Entity]:
        """The entries of ``children:`` (or of the list the entry is)."""
        items = self.element
        if isinstance(items, dict) and self.kind != "launch":
            if "children" not in items:
                raise self.fail(f"{self.label} needs 'children:', a list of entries")
            items = items["children"]
        if not isinstance(items, list):
            raise self.fail("expected a list of launch entries (- arg:, - node:, - include: ...)")
        found: list[Entity] = []
        for item in items:
            keys = [k for k in item if k != LINE] if isinstance(item, dict) else []
            if len(keys) != 1:
                line = item.get(LINE, self.line) if isinstance(item, dict) else self.line
                raise LaunchError(
                    f"{self.path}:{line}: each launch entry is a single key such as "
                    "'node:' or 'arg:'"
                )
            element = item[keys[0]]
            line = element.get(LINE, item[LINE]) if isinstance(element, dict) else item[LINE]
            found.append(YamlEntity(self.path, line, str(keys[0]), element))
        return found

    def check(self, tag: Tag, guarded: bool) -> None:
        """Refuse a key the entry does not have (a typo would otherwise be ignored)."""
        if isinstance(self.element, list) and tag.children:
            return
        if self.element is None:
            return
        if not isinstance(self.element, dict):
            raise self.fail(f"{self.label} must be a mapping of attributes, not {self.element!r}")
        known = set(tag.attributes) | set(tag.nested)
        known |= ({"children"} if tag.children else set()) | (
            {"if", "unless"} if guarded else set()
        )
        for key in self.element:
            if key != LINE and key not in known:
                raise self.unknown(str(key), known, "attribute")


def load_yaml(path: Path) -> LaunchDescription:
    """Read a YAML launch file.

    Raises:
        LaunchError: not YAML, no top-level ``launch:`` list, or a bad entry (with its line).
    """
    try:
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=_Loader)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        line = mark.line + 1 if mark is not None else 0
        raise LaunchError(
            f"{path}:{line}: not valid YAML: {getattr(err, 'problem', err)}"
        ) from None
    except (OSError, UnicodeDecodeError) as err:
        raise LaunchError(f"{path}: cannot read: {err}") from None
    if not isinstance(data, dict) or "launch" not in data:
        raise LaunchError(
            f"{path}:1: a YAML launch file starts with 'launch:' and a list of entries"
        )
    return build_description(YamlEntity(path, data.get(LINE, 1), "launch", data["launch"]))
