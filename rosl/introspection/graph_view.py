"""``rosl graph``: rqt_graph's picture without a GUI, as DOT, Mermaid or an indented text tree.

Unlike rqt_graph, everything is shown by default: a topic nobody subscribes to is drawn and
labelled ``dead sink``, one with a single connection ``leaf``. The hide filters are opt-in.
An action is drawn once (action clients -> action -> servers), as rqt_graph's "Actions" group
draws its hidden ``_action/`` topics as one box.
The model is plain data (:class:`GraphModel`); the renderers are pure functions of it, sorted,
so the same graph always gives the same text.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from rosl.graph import actions
from rosl.graph.records import CLIENT, PUBLISHER, SUBSCRIPTION, is_hidden
from rosl.introspection.errors import IntrospectionError

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator
    from pathlib import Path

    from rosl.graph.cache import GraphCache
    from rosl.introspection.session import Session

# rqt_graph's "Debug" filter (dotcode.py QUIET_NAMES): substrings of node and topic names
DEBUG_NAMES = (
    "/diag_agg",
    "/runtime_logger",
    "/pr2_dashboard",
    "/rviz",
    "/rosout",
    "/cpu_monitor",
    "/monitor",
    "/hd_monitor",
    "/rxloggerlevel",
    "/clock",
    "/rqt",
    "/statistics",
)
PARAM_NAMES = (
    "parameter_events",
    "parameter_updates",
    "describe_parameters",
    "get_parameter_types",
    "get_parameters",
    "list_parameters",
    "set_parameters",
    "set_parameters_atomically",
)
GRAPHVIZ_FORMATS = ("svg", "png", "pdf")
TEXT_FORMATS = {
    ".dot": "dot",
    ".gv": "dot",
    ".mmd": "mermaid",
    ".mermaid": "mermaid",
    ".txt": "text",
}
SETTLE_S = 0.2  # --watch: let a burst of changes (a launch) settle into one snapshot


@dataclass(frozen=True, slots=True)
class GraphOptions:
    """What to draw; every hide filter is off by default."""

    services: bool = False
    nodes_only: bool = False
    hide_dead_sinks: bool = False
    hide_leaf_topics: bool = False
    hide_debug: bool = False
    hide_params: bool = False
    include: tuple[str, ...] = ()
    exclude: tuple[str, ...] = ()
    include_hidden: bool = False


@dataclass(frozen=True, slots=True)
class Channel:
    """A topic (publishers → subscribers), a service or an action (clients → servers)."""

    name: str
    kind: str  # "topic", "service" or "action"
    types: tuple[str, ...]
    sources: tuple[str, ...]  # node names: publishers or clients
    sinks: tuple[str, ...]  # node names: subscribers or servers
    marks: tuple[str, ...] = ()
    unseen_sources: int = 0  # sources / sinks that a filter took out of the picture
    unseen_sinks: int = 0


@dataclass(frozen=True, slots=True)
class GraphModel:
    """The nodes (name → how many share it) and channels to draw."""

    nodes: dict[str, int] = field(default_factory=dict)
    channels: tuple[Channel, ...] = ()

    @property
    def topics(self) -> list[Channel]:
        """The topics, sorted by name."""
        return [c for c in self.channels if c.kind == "topic"]

    @property
    def services(self) -> list[Channel]:
        """The services, sorted by name."""
        return [c for c in self.channels if c.kind == "service"]

    @property
    def actions(self) -> list[Channel]:
        """The actions, sorted by name."""
        return [c for c in self.channels if c.kind == "action"]


# --- the model -------------------------------------------------------------------------------


def build(graph: GraphCache, options: GraphOptions, own_process: int | None = None) -> GraphModel:
    """Turn the discovered graph into the picture's model: marks first, then the filters."""
    shown: Callable[[str], bool] = (
        (lambda name: True) if options.include_hidden else (lambda name: not is_hidden(name))
    )
    nodes: dict[str, int] = {}
    ends: dict[tuple[str, str], tuple[set[str], set[str], set[str]]] = {}
    for node in graph.nodes():
        if node.process == own_process or not shown(node.fqn):
            continue
        nodes[node.fqn] = nodes.get(node.fqn, 0) + 1
        for endpoint in node.endpoints:
            kind = "topic" if endpoint.kind in (PUBLISHER, SUBSCRIPTION) else "service"
            if not shown(endpoint.name) or (kind == "service" and not options.services):
                continue
            types, sources, sinks = ends.setdefault((endpoint.name, kind), (set(), set(), set()))
            types.add(endpoint.type)
            (sources if endpoint.kind in (PUBLISHER, CLIENT) else sinks).add(node.fqn)
        for side, named in ((1, actions.clients(node)), (2, actions.servers(node))):
            for name, action_types in named.items():
                sets = ends.setdefault((name, "action"), (set(), set(), set()))
                sets[0].update(action_types)
                sets[side].add(node.fqn)
    channels = tuple(_channel(name, kind, *sets) for (name, kind), sets in sorted(ends.items()))
    return _filtered(GraphModel(dict(sorted(nodes.items())), channels), options)


def _channel(name: str, kind: str, types: set[str], sources: set[str], sinks: set[str]) -> Channel:
    marks = []
    if kind == "topic":
        if not sinks:
            marks.append("dead sink")
        if len(sources) + len(sinks) == 1:
            marks.append("leaf")
    elif not sinks:
        marks.append("no server")
    elif kind == "action" and not sources:
        marks.append("no client")
    if len(types) > 1:
        marks.append(f"{len(types)} types")
    if is_hidden(name):
        marks.append("hidden")
    return Channel(
        name, kind, tuple(sorted(types)), tuple(sorted(sources)), tuple(sorted(sinks)),
        tuple(marks),
    )  # fmt: skip


def _compile(patterns: tuple[str, ...]) -> list[re.Pattern[str]]:
    compiled = []
    for pattern in patterns:
        try:
            compiled.append(re.compile(pattern))
        except re.error as err:
            raise IntrospectionError(f"bad regular expression '{pattern}': {err.msg}") from None
    return compiled


def _is_debug(name: str) -> bool:
    last = name.rstrip("/").rsplit("/", 1)[-1]
    return last.startswith("_") or any(word in name for word in DEBUG_NAMES)


def _filtered(model: GraphModel, options: GraphOptions) -> GraphModel:
    include, exclude = _compile(options.include), _compile(options.exclude)

    def dropped(name: str) -> bool:
        return (options.hide_debug and _is_debug(name)) or any(p.search(name) for p in exclude)

    def hidden_channel(c: Channel) -> bool:
        return (
            dropped(c.name)
            or (options.hide_params and c.name.rsplit("/", 1)[-1] in PARAM_NAMES)
            or (options.hide_dead_sinks and "dead sink" in c.marks)
            or (options.hide_leaf_topics and "leaf" in c.marks)
        )

    nodes = {n: k for n, k in model.nodes.items() if not dropped(n)}
    channels = [c for c in model.channels if not hidden_channel(c)]
    if include:  # keep what matches, with its direct neighbours
        matched = {n for n in nodes if any(p.search(n) for p in include)}
        picked = [c for c in channels if any(p.search(c.name) for p in include)]
        chosen = matched | {n for c in picked for n in (*c.sources, *c.sinks)}
        channels = [c for c in channels if c in picked or matched & {*c.sources, *c.sinks}]
        nodes = {n: k for n, k in nodes.items() if n in chosen}
    kept = []
    for c in channels:
        sources = tuple(n for n in c.sources if n in nodes)
        sinks = tuple(n for n in c.sinks if n in nodes)
        if sources or sinks:  # a channel whose every node was filtered out is not drawn
            unseen = (len(c.sources) - len(sources), len(c.sinks) - len(sinks))
            kept.append(replace(c, sources=sources, sinks=sinks, unseen_sources=unseen[0],
                                unseen_sinks=unseen[1]))  # fmt: skip
    return GraphModel(nodes, tuple(kept))


def model(session: Session, options: GraphOptions) -> GraphModel:
    """The model of the live graph (one complete query); never shows this process."""
    return build(session.graph(), options, session.participant.sender)


# --- renderers -------------------------------------------------------------------------------


def _label(channel: Channel) -> list[str]:
    return [channel.name, f"[{', '.join(channel.marks)}]"] if channel.marks else [channel.name]


def _q(*lines: str) -> str:
    r"""A quoted DOT string; several lines are joined with DOT's ``\n``."""
    return '"' + "\\n".join(t.replace("\\", "\\\\").replace('"', '\\"') for t in lines) + '"'


def _loose_ends(m: GraphModel, node: str) -> list[str]:
    """In nodes-only pictures: the node's topics that lead nowhere, so they stay visible."""
    out = [
        f"-> {c.name}{_marks(c)}{_unseen(c.unseen_sinks)}"
        for c in m.topics
        if node in c.sources and not c.sinks
    ]
    return out + [
        f"<- {c.name}{_marks(c)}{_unseen(c.unseen_sources)}"
        for c in m.topics
        if node in c.sinks and not c.sources
    ]


def _unseen(count: int) -> str:
    return f" ({count} filtered out)" if count else ""


def _across(names: tuple[str, ...], unseen: int, none: str) -> str:
    """Who is across a channel: the names shown, and how many a filter left out."""
    if not unseen:
        return ", ".join(names) or none
    return ", ".join([*names, f"{'+' if names else ''}{unseen} filtered out"])


def _marks(channel: Channel) -> str:
    return f" [{', '.join(channel.marks)}]" if channel.marks else ""


def _node_label(m: GraphModel, node: str, nodes_only: bool) -> list[str]:
    count = m.nodes[node]
    lines = [node if count == 1 else f"{node} (x{count}, duplicate name)"]
    return lines + _loose_ends(m, node) if nodes_only else lines


def _pairs(m: GraphModel, kind: str) -> dict[tuple[str, str], list[str]]:
    pairs: dict[tuple[str, str], list[str]] = {}
    for c in m.channels:
        if c.kind == kind:
            for src in c.sources:
                for dst in c.sinks:
                    pairs.setdefault((src, dst), []).append(c.name)
    return dict(sorted(pairs.items()))


_PREFIX = {"topic": "t:", "service": "s:", "action": "a:"}
_SHAPES = {"topic": "box", "service": "diamond", "action": "hexagon"}


def to_dot(m: GraphModel, nodes_only: bool = False) -> str:
    """The picture as Graphviz DOT (node ids ``n:``, topics ``t:``, services ``s:``, ``a:``)."""
    out = ["digraph rosgraph {", "  rankdir=LR;", "  node [fontsize=10];"]
    for node in m.nodes:
        out.append(
            f"  {_q('n:' + node)} [label={_q(*_node_label(m, node, nodes_only))}, shape=ellipse];"
        )
    if nodes_only:
        for kind, style in (
            ("topic", ""),
            ("service", ", style=dashed"),
            ("action", ", style=bold"),
        ):
            for (src, dst), names in _pairs(m, kind).items():
                out.append(f"  {_q('n:' + src)} -> {_q('n:' + dst)} [label={_q(*names)}{style}];")
        return "\n".join([*out, "}"]) + "\n"
    for c in m.channels:
        ident = _q(_PREFIX[c.kind] + c.name)
        loose = {"dead sink", "no server"} & set(c.marks)
        color = ', color="red"' if loose else ', color="orange"' if "leaf" in c.marks else ""
        out.append(f"  {ident} [label={_q(*_label(c))}, shape={_SHAPES[c.kind]}{color}];")
    for c in m.channels:
        ident = _q(_PREFIX[c.kind] + c.name)
        style = {"topic": "", "service": " [style=dashed]", "action": " [style=bold]"}[c.kind]
        out += [f"  {_q('n:' + src)} -> {ident}{style};" for src in c.sources]
        out += [f"  {ident} -> {_q('n:' + dst)}{style};" for dst in c.sinks]
    return "\n".join([*out, "}"]) + "\n"


def _mq(lines: list[str]) -> str:
    return '"' + "<br/>".join(s.replace('"', "#quot;") for s in lines) + '"'


def to_mermaid(m: GraphModel, nodes_only: bool = False) -> str:
    """The picture as a Mermaid flowchart (nodes rounded, topics boxes, services rhombi)."""
    ids = {("node", n): f"n{i}" for i, n in enumerate(m.nodes, 1)}
    out = ["flowchart LR"]
    out += [f"  {ids['node', n]}([{_mq(_node_label(m, n, nodes_only))}])" for n in m.nodes]
    if nodes_only:
        for kind, arrow in (("topic", "-->"), ("service", "-.->"), ("action", "==>")):
            for (src, dst), names in _pairs(m, kind).items():
                out.append(f"  {ids['node', src]} {arrow}|{_mq(names)}| {ids['node', dst]}")
        return "\n".join(out) + "\n"
    warned = []
    for i, c in enumerate(m.channels, 1):
        ident = ids[c.kind, c.name] = c.kind[0] + str(i)
        text = _mq(_label(c))
        opening, closing = {"topic": ("[", "]"), "service": ("{", "}"), "action": ("{{", "}}")}[
            c.kind
        ]
        out.append(f"  {ident}{opening}{text}{closing}")
        if {"dead sink", "no server", "leaf"} & set(c.marks):
            warned.append(ident)
    for c in m.channels:
        arrow = {"topic": "-->", "service": "-.->", "action": "==>"}[c.kind]
        out += [f"  {ids['node', s]} {arrow} {ids[c.kind, c.name]}" for s in c.sources]
        out += [f"  {ids[c.kind, c.name]} {arrow} {ids['node', d]}" for d in c.sinks]
    if warned:
        out += [
            "  classDef loose stroke:#c0392b,stroke-dasharray:4 2;",
            f"  class {','.join(warned)} loose;",
        ]
    return "\n".join(out) + "\n"


def to_text(m: GraphModel) -> str:
    """Each node with what it publishes/subscribes (and serves/calls), and who is across."""
    if not m.nodes:
        return "(no nodes)\n"
    out = []
    sections = (
        ("publishes", "topic", "sources", "sinks", "->", "nobody"),
        ("subscribes", "topic", "sinks", "sources", "<-", "nobody"),
        ("serves", "service", "sinks", "sources", "<-", "no client"),
        ("calls", "service", "sources", "sinks", "->", "no server"),
        ("serves actions", "action", "sinks", "sources", "<-", "no client"),
        ("sends goals", "action", "sources", "sinks", "->", "no server"),
    )
    for node in m.nodes:
        out.append(_node_label(m, node, False)[0])
        for title, kind, mine, theirs, arrow, none in sections:
            rows = [c for c in m.channels if c.kind == kind and node in getattr(c, mine)]
            if rows:
                out.append(f"  {title}:")
            for c in rows:
                other = _across(getattr(c, theirs), getattr(c, f"unseen_{theirs}"), none)
                out.append(f"    {c.name} [{', '.join(c.types)}] {arrow} {other}{_marks(c)}")
    return "\n".join(out) + "\n"


def render(m: GraphModel, fmt: str, nodes_only: bool = False) -> str:
    """The model in one of ``dot``, ``mermaid``, ``text``."""
    if fmt == "mermaid":
        return to_mermaid(m, nodes_only)
    return to_text(m) if fmt == "text" else to_dot(m, nodes_only)


# --- files and --watch ------------------------------------------------------------------------


def output_format(path: Path) -> str:
    """The format a file name asks for; checks that Graphviz is there for svg/png/pdf.

    Raises:
        IntrospectionError: an unknown suffix, or Graphviz's ``dot`` is missing.
    """
    suffix = path.suffix.lower()
    if suffix in TEXT_FORMATS:
        return TEXT_FORMATS[suffix]
    if suffix.lstrip(".") in GRAPHVIZ_FORMATS:
        require_graphviz(suffix.lstrip("."), "-o FILE.dot / --mermaid")
        return suffix.lstrip(".")
    known = ", ".join([*TEXT_FORMATS, *(f".{f}" for f in GRAPHVIZ_FORMATS)])
    raise IntrospectionError(f"cannot write '{path}': unknown file type (use {known})")


def require_graphviz(fmt: str, alternative: str) -> str:
    """The path of Graphviz's ``dot``, or a one-line error saying how to get it."""
    found = shutil.which("dot")
    if found is None:
        raise IntrospectionError(
            f"graphviz's 'dot' is not installed (needed for .{fmt}): apt install graphviz, "
            f"or use {alternative}"
        )
    return found


def write(path: Path, text: str, fmt: str) -> None:
    """Write text, or run DOT text through Graphviz into an svg/png/pdf (never a half file).

    Raises:
        IntrospectionError: Graphviz failed, or the file cannot be written.
    """
    data = text.encode()
    if fmt in GRAPHVIZ_FORMATS:
        dot = require_graphviz(fmt, "-o FILE.dot")
        try:
            done = subprocess.run(
                [dot, f"-T{fmt}"], input=data, capture_output=True, timeout=60, check=False
            )
        except (OSError, subprocess.TimeoutExpired) as err:
            raise IntrospectionError(f"graphviz's 'dot' failed: {err}") from None
        if done.returncode != 0:
            reason = done.stderr.decode(errors="replace").strip().splitlines()
            raise IntrospectionError(f"graphviz's 'dot' failed: {reason[0] if reason else '?'}")
        data = done.stdout
    try:
        path.write_bytes(data)
    except OSError as err:
        raise IntrospectionError(f"cannot write '{path}': {err.strerror}") from None


def export(session: Session, options: GraphOptions, path: Path) -> None:
    """Write the picture to ``path`` in the format its suffix names."""
    fmt = output_format(path)
    m = model(session, options)
    text = render(m, fmt if fmt in ("mermaid", "text") else "dot", options.nodes_only)
    write(path, text, fmt)


def watch(session: Session, options: GraphOptions, fmt: str) -> Iterator[str]:
    """Yield the picture now and again each time it changes (until Ctrl-C)."""
    graph = session.graph()
    own = session.participant.sender
    last = ""
    while True:
        generation = graph.generation
        text = render(build(graph, options, own), fmt, options.nodes_only)
        if text != last:
            last = text
            yield text
        if graph.wait_change(generation, timeout=1.0) != generation:
            graph.wait_change(graph.generation, timeout=SETTLE_S)
