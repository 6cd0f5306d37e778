"""``rosl tf``: the TF frame tree (view_frames, without Graphviz) and transforms (tf2_echo).

Listens to ``/tf`` and ``/tf_static`` (the latter transient-local, so a late listener still gets
the static transforms). The transforms go into :mod:`rosl.tf2`'s frame tree, the same one
``tf2_ros.Buffer`` is, so ``rosl tf echo`` and ``tf2_echo`` compute alike (time 0 is the latest
common time, edges are interpolated). Beside it each edge keeps what the tree does not: which
publisher sent it (so the broadcaster shown is the node that really broadcast that edge) and a
short history of receive times, for the rate.
"""

from __future__ import annotations

import difflib
import time
from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.graph.records import PUBLISHER
from rosl.introspection.errors import IntrospectionError
from rosl.tf2.echo import echo_text as _tf2_echo_text
from rosl.tf2.errors import TransformException
from rosl.tf2.messages import transform_of
from rosl.tf2.tree import FrameTree

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

    from rosl.introspection.session import Session
    from rosl.tf2.transform import Transform

TOPICS = ("/tf", "/tf_static")
HISTORY = 100  # receive times kept per edge, for the rate
DRAWN = ("svg", "png", "pdf")  # pictures rosl can draw itself


# --- the buffer -------------------------------------------------------------------------------


@dataclass(slots=True)
class Edge:
    """An edge parent→child as heard: its latest stamp, who sent it, recent receive times (ns)."""

    parent: str
    child: str
    static: bool
    stamp_ns: int
    senders: set[tuple[int, int]] = field(default_factory=set)
    received: deque[int] = field(default_factory=lambda: deque(maxlen=HISTORY))
    oldest_stamp_ns: int = 0
    broadcasters: tuple[str, ...] = ()

    @property
    def rate(self) -> float | None:
        """Messages per second over the kept history (None with fewer than two)."""
        if len(self.received) < 2 or self.received[-1] <= self.received[0]:
            return None
        return (len(self.received) - 1) * 1e9 / (self.received[-1] - self.received[0])


class TfBuffer:
    """The frame tree (lookups) and, by child frame, what was heard of each edge."""

    def __init__(self) -> None:
        self.edges: dict[str, Edge] = {}
        self.tree = FrameTree()

    def add(self, message: Any, static: bool, sender: tuple[int, int], received_ns: int) -> None:
        """Store every transform of a ``tf2_msgs/msg/TFMessage``."""
        for ts in message.transforms:
            parent, child = ts.header.frame_id.lstrip("/"), ts.child_frame_id.lstrip("/")
            stamp = ts.header.stamp.sec * 1_000_000_000 + ts.header.stamp.nanosec
            transform = transform_of(ts)
            if not self.tree.insert(parent, child, stamp, transform, "", static):
                self.tree.clear()  # time went back past the cache (a bag looping): start over
                self.tree.insert(parent, child, stamp, transform, "", static)
            edge = self.edges.get(child)
            if edge is None or edge.parent != parent or edge.static != static:
                edge = self.edges[child] = Edge(parent, child, static, stamp)
                edge.oldest_stamp_ns = stamp
            edge.stamp_ns = stamp
            edge.senders.add(sender)
            edge.received.append(received_ns)

    def frames(self) -> set[str]:
        """Every frame named as a parent or a child."""
        return {*self.edges, *(e.parent for e in self.edges.values())}

    def path_to_root(self, frame: str) -> list[str]:
        """``frame``, its parent, ... up to its root (stops on a cycle)."""
        path = [frame]
        while path[-1] in self.edges and self.edges[path[-1]].parent not in path:
            path.append(self.edges[path[-1]].parent)
        return path

    def roots(self) -> list[str]:
        """Frames without a parent, sorted."""
        return sorted(f for f in self.frames() if f not in self.edges)

    def children(self, frame: str) -> list[Edge]:
        """The edges below ``frame``, sorted by child name."""
        return sorted((e for e in self.edges.values() if e.parent == frame), key=lambda e: e.child)

    def lookup(self, source: str, target: str) -> tuple[Transform, int]:
        """The pose of ``target`` in ``source`` (tf2_echo SOURCE TARGET) and its stamp (ns).

        Looked up at the latest common time of the edges between them, as tf2_echo does.

        Raises:
            IntrospectionError: a frame is unknown, the two are not connected, or tf2 cannot
                compute it (an extrapolation, in tf2's words).
        """
        for frame in (source, target):
            if frame not in self.frames():
                raise IntrospectionError(_unknown_frame(frame, self.frames()))
        up_source, up_target = self.path_to_root(source), self.path_to_root(target)
        if not set(up_source) & set(up_target):
            raise IntrospectionError(
                f"frames '{source}' and '{target}' are not connected: '{source}' is in the tree "
                f"of '{up_source[-1]}', '{target}' in the tree of '{up_target[-1]}'"
            )
        try:
            return self.tree.lookup(source, target, 0)
        except TransformException as err:
            raise IntrospectionError(str(err).splitlines()[0]) from None


def _unknown_frame(frame: str, known: set[str]) -> str:
    ranked = sorted(known, key=lambda k: (-difflib.SequenceMatcher(None, frame, k).ratio(), k))
    return f"frame '{frame}' does not exist; known frames: {', '.join(ranked)}"


# --- listening --------------------------------------------------------------------------------


class TfListener:
    """Subscribes to /tf and /tf_static with the command's hidden node."""

    def __init__(self, session: Session) -> None:
        import rosl
        from rosl.node.qos import DurabilityPolicy, QoSProfile

        self.session = session
        self.buffer = TfBuffer()
        msg_type: Any = rosl.get_interface("tf2_msgs/msg/TFMessage")
        node = session.node()
        durabilities = (DurabilityPolicy.VOLATILE, DurabilityPolicy.TRANSIENT_LOCAL)
        for topic, durability in zip(TOPICS, durabilities, strict=True):
            node.create_subscription(
                msg_type,
                topic,
                self._callback(topic == "/tf_static"),
                QoSProfile(depth=100, durability=durability),
            )
        self._executor = rosl.SingleThreadedExecutor()
        self._executor.add_node(node)

    def _callback(self, static: bool) -> Any:
        def deliver(message: Any, info: dict[str, Any]) -> None:
            received = info.get("received_timestamp") or time.time_ns()
            self.buffer.add(message, static, tuple(info["publisher_gid"]), received)

        return deliver

    def spin_for(self, seconds: float) -> bool:
        """Take messages for ``seconds``; False as soon as Ctrl-C (or SIGTERM) asked to stop."""
        import rosl

        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0:
            if not rosl.ok():
                return False
            self._executor.spin_once(timeout_sec=min(left, 0.05))
        return rosl.ok()

    def name_broadcasters(self) -> None:
        """Fill each edge's broadcaster names from the graph (by publisher id)."""
        publishers = {
            (node.process, e.endpoint): (node.fqn, e.name)
            for topic in TOPICS
            for node, e in self.session.graph(fresh=True).endpoints(PUBLISHER, topic)
        }
        for edge in self.buffer.edges.values():
            topic = TOPICS[edge.static]
            names = {publishers[s][0] for s in edge.senders if s in publishers}
            if not names:  # publisher gone meanwhile: everyone publishing that topic
                names = {n for n, t in publishers.values() if t == topic} or {"unknown"}
            edge.broadcasters = tuple(sorted(names))


def _no_data(wait_time: float) -> IntrospectionError:
    return IntrospectionError(f"no TF data received on /tf or /tf_static within {wait_time} s")


def frames(session: Session, wait_time: float) -> TfBuffer:
    """Listen for ``wait_time`` seconds and return what was heard.

    Raises:
        IntrospectionError: no transform at all arrived.
    """
    listener = TfListener(session)
    if not listener.spin_for(wait_time):
        raise KeyboardInterrupt
    if not listener.buffer.edges:
        raise _no_data(wait_time)
    listener.name_broadcasters()
    return listener.buffer


def echo(
    session: Session, source: str, target: str, *, wait_time: float, once: bool, rate: float
) -> Iterator[str]:
    """Yield tf2_echo's block for SOURCE→TARGET now, then every ``1/rate`` s (until Ctrl-C).

    Raises:
        IntrospectionError: no data, an unknown frame, or frames not connected within the wait.
    """
    listener = TfListener(session)
    deadline = time.monotonic() + wait_time
    while listener.spin_for(0.05):
        try:
            transform, stamp = listener.buffer.lookup(source, target)
            break
        except IntrospectionError:
            if time.monotonic() < deadline:
                continue
            if not listener.buffer.edges:
                raise _no_data(wait_time) from None
            raise
    else:
        return
    block = echo_text(transform, stamp)
    while True:
        yield block
        if once or not listener.spin_for(1.0 / rate if rate > 0 else 1.0):
            return
        try:
            block = echo_text(*listener.buffer.lookup(source, target))
        except IntrospectionError as err:  # tf2_echo reports a failure and goes on
            block = f"Failure at {time.time():f}\nException thrown:{err}"


# --- rendering --------------------------------------------------------------------------------


def echo_text(transform: Transform, stamp_ns: int) -> str:
    """tf2_echo's block: time, translation, quaternion, RPY in radians and degrees, matrix."""
    return _tf2_echo_text(transform, stamp_ns)


def _about(edge: Edge) -> str:
    who = ", ".join(edge.broadcasters) or "unknown"
    if edge.static:
        return f"broadcaster: {who}, static"
    rate = edge.rate
    return f"broadcaster: {who}, average rate: {rate:.1f} Hz" if rate else f"broadcaster: {who}"


def _walk(buffer: TfBuffer) -> Iterator[tuple[int, Edge | None, str]]:
    """(depth, edge into the frame or None for a root, frame), depth first, sorted."""
    seen: set[str] = set()

    def below(frame: str, depth: int) -> Iterator[tuple[int, Edge | None, str]]:
        for edge in buffer.children(frame):
            if edge.child not in seen:
                seen.add(edge.child)
                yield depth, edge, edge.child
                yield from below(edge.child, depth + 1)

    for root in buffer.roots():
        seen.add(root)
        yield 0, None, root
        yield from below(root, 1)
    for frame in sorted(buffer.frames() - seen):  # frames in a cycle have no root
        seen.add(frame)
        yield 0, None, f"{frame} (in a cycle)"
        yield from below(frame, 1)


def frames_text(buffer: TfBuffer) -> str:
    """The tree as indented text, roots first."""
    lines = [
        f"{'  ' * depth}{frame}" + (f"  ({_about(edge)})" if edge else "")
        for depth, edge, frame in _walk(buffer)
    ]
    roots = buffer.roots()
    if len(roots) > 1:
        lines.append(f"note: {len(roots)} separate trees (roots: {', '.join(roots)})")
    return "\n".join(lines) + "\n"


def frames_dot(buffer: TfBuffer, recorded_ns: int | None = None) -> str:
    """view_frames' DOT: one labelled edge per transform and the 'Recorded at time' legend."""
    out = ["digraph G {"]
    for _, edge, _ in _walk(buffer):
        if edge is None:
            continue
        span = 0.0 if edge.static else (edge.received[-1] - edge.received[0]) / 1e9
        rate = "static" if edge.static else f"{round(edge.rate or 0.0, 3)}"
        out.append(
            f'"{edge.parent}" -> "{edge.child}"[label=" Broadcaster: '
            f"{', '.join(edge.broadcasters) or 'unknown'}\\nAverage rate: {rate}\\n"
            f"Buffer length: {round(span, 3)}\\nMost recent transform: {edge.stamp_ns / 1e9}\\n"
            f'Oldest transform: {edge.oldest_stamp_ns / 1e9}\\n"];'
        )
    recorded = (time.time_ns() if recorded_ns is None else recorded_ns) / 1e9
    root = next(iter(buffer.roots()), next(iter(sorted(buffer.frames())), ""))
    out += [
        "edge [style=invis];",
        ' subgraph cluster_legend { style=bold; color=black; label ="view_frames Result";',
        f'"Recorded at time: {recorded}"[ shape=plaintext ] ;',
        f'}}->"{root}";',
        "}",
    ]
    return "\n".join(out) + "\n"


def output_format(path: Path) -> str:
    """``dot``, ``text`` or a Graphviz format for ``-o``; checks Graphviz is there first.

    Raises:
        IntrospectionError: an unknown suffix, or Graphviz's ``dot`` is missing.
    """
    from rosl.introspection.graph_view import GRAPHVIZ_FORMATS, require_graphviz

    suffix = path.suffix.lower().lstrip(".")
    if suffix in ("dot", "gv", "txt"):
        return "text" if suffix == "txt" else "dot"
    if suffix in DRAWN:  # Graphviz when it is there, else rosl's own drawing
        return suffix
    if suffix in GRAPHVIZ_FORMATS:
        require_graphviz(suffix, "-o FILE.dot, or the text tree")
        return suffix
    raise IntrospectionError(
        f"cannot write '{path}': unknown file type (use .dot, .gv, .txt, "
        f"{', '.join('.' + f for f in GRAPHVIZ_FORMATS)})"
    )


def export(buffer: TfBuffer, path: Path) -> None:
    """Write the tree to ``path``: text, DOT, or a picture.

    Pictures (svg/png/pdf) come from Graphviz when it is installed, else from
    :mod:`rosl.introspection.tf_picture`.
    """
    import shutil

    from rosl.introspection.graph_view import write

    fmt = output_format(path)
    if fmt in DRAWN and shutil.which("dot") is None:
        from rosl.introspection import tf_picture

        tf_picture.write(buffer, path)
        return
    write(path, frames_text(buffer) if fmt == "text" else frames_dot(buffer), fmt)
