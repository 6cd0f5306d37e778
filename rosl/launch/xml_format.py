"""ROS 2's XML launch format (``*.launch.xml``), read with line numbers.

::

    <launch>
      <arg name="topic" default="chatter" description="..."/>
      <node pkg="tutorial_pkg" exec="my_publisher" name="talker" namespace="demo" output="screen">
        <param name="rate" value="2.0"/>
        <param from="$(find-pkg-share tutorial_pkg)/params.yaml"/>
        <remap from="my_data" to="$(var topic)"/>
      </node>
      <include file="$(dirname)/other.launch.py"><arg name="x" value="1"/></include>
    </launch>

The file is parsed with the standard library's expat (every element keeps its line); the tags
become actions through :mod:`rosl.launch.frontend`, the path YAML launch files take too.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any
from xml.parsers import expat

from rosl.launch.errors import LaunchError
from rosl.launch.frontend import Entity, Tag, build_description
from rosl.launch.ros_actions import yaml_typed

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.launch.description import LaunchDescription


@dataclass(slots=True)
class Element:
    """An XML element: tag, attributes (in order), line, children and text."""

    tag: str
    attributes: dict[str, str]
    line: int
    children: list[Element] = field(default_factory=list)
    text: list[str] = field(default_factory=list)


def parse_xml(path: Path) -> Element:
    """The root element of an XML file, every element with its line.

    Raises:
        LaunchError: unreadable, or not well-formed XML (``file:line: not valid XML: ...``).
    """
    try:
        data = path.read_bytes()
    except OSError as err:
        raise LaunchError(f"{path}: cannot read: {err.strerror}") from None
    parser = expat.ParserCreate()
    stack: list[Element] = []
    roots: list[Element] = []

    def start(tag: str, attributes: dict[str, str]) -> None:
        element = Element(tag, attributes, parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    def end(tag: str) -> None:
        stack.pop()

    def text(data: str) -> None:
        if stack:
            stack[-1].text.append(data)

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = text
    try:
        parser.Parse(data, True)
    except expat.ExpatError as err:
        reason = expat.errors.messages.get(err.code, str(err))
        raise LaunchError(f"{path}:{err.lineno}: not valid XML: {reason}") from None
    return roots[0]


class XmlEntity(Entity):
    """An element as the frontend reads it; ``X-sep`` splits attribute ``X`` into a list."""

    noun = "tag"

    def __init__(self, path: Path, element: Element) -> None:
        super().__init__(path, element.line, element.tag)
        self.element = element

    @property
    def label(self) -> str:
        """``<node>``."""
        return f"<{self.kind}>"

    def value(self, name: str) -> Any:
        """The attribute's text, or a list of texts when ``name-sep`` is given."""
        attributes = self.element.attributes
        if name not in attributes:
            return None
        separator = attributes.get(f"{name}-sep")
        if separator is None:
            return attributes[name]
        if not separator:
            raise self.fail(f"attribute '{name}-sep' of {self.label} is empty")
        return attributes[name].split(separator)

    def nested(self, name: str) -> list[Entity]:
        """Child elements called ``name``."""
        return [XmlEntity(self.path, e) for e in self.element.children if e.tag == name]

    def actions(self) -> list[Entity]:
        """Every child element (its nested entities were refused by ``check`` if misplaced)."""
        return [XmlEntity(self.path, e) for e in self.element.children]

    def check(self, tag: Tag, guarded: bool) -> None:
        """Refuse unknown attributes, unknown child tags and stray text."""
        known = set(tag.attributes) | ({"if", "unless"} if guarded else set())
        for name in self.element.attributes:
            if ":" in name or name == "xmlns":  # xmlns:..., xsi:... — not launch attributes
                continue
            base = name.removesuffix("-sep") if name.endswith("-sep") else name
            if base not in known or (base != name and base not in self.element.attributes):
                raise self.unknown(name, known, "attribute")
        if not tag.children:
            for child in self.element.children:
                if child.tag not in tag.nested:
                    raise XmlEntity(self.path, child).unknown_child(self, tag)
        text = "".join(self.element.text).strip()
        if text:
            shown = text if len(text) <= 30 else text[:27] + "..."
            raise self.fail(f"unexpected text '{shown}' in {self.label}")

    def unknown_child(self, parent: XmlEntity, tag: Tag) -> LaunchError:
        """``unknown tag <parm> in <node> (did you mean 'param'?)``."""
        from rosl.idl.names import did_you_mean

        nested = ", ".join(sorted(tag.nested)) or "no tags"
        return self.fail(
            f"unknown tag {self.label} in {parent.label}{did_you_mean(self.kind, tag.nested)} "
            f"({parent.label} holds: {nested})"
        )

    def typed(self, text: str) -> Any:
        """XML values are text: ``2.0`` is a float, ``true`` a bool, as launch_ros reads them."""
        return yaml_typed(text)


_ROOT = Tag(frozenset({"version", "deprecated"}), children=True)


def load_xml(path: Path) -> LaunchDescription:
    """Read an XML launch file.

    Raises:
        LaunchError: not XML, a root other than ``<launch>``, or a bad tag (with its line).
    """
    root = XmlEntity(path, parse_xml(path))
    if root.kind != "launch":
        raise root.fail(f"the root tag of a launch file is <launch>, not {root.label}")
    root.check(_ROOT, guarded=False)
    return build_description(root)
