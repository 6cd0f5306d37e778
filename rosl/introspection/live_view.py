"""``rosl viz --serve``: the live world and the node graph in a web page that rosl serves.

The state is :class:`~rosl.introspection.viz.VizBuilder`'s, so the page draws what ``rosl viz``
draws in its PNG: the world's markers, footprints and frames, odometry paths and the last scan,
in the fixed frame chosen the same way. The main thread spins a hidden node that feeds the
builder, and a few times a second turns it into a small JSON snapshot (rounded to millimetres,
paths decimated); the graph (``rosl graph``'s model) is sent again whenever it changes.
index.html is served with the latest snapshots inside it, so the page draws at once.

Why the standard library's ``http.server`` and server-sent events: the page only listens, so
one-way events are enough; SSE is plain HTTP (``EventSource`` reconnects by itself, ``curl``
and ``urllib`` can read it), needs no new dependency and no protocol code of our own, and the
page, its script and its style are files shipped in ``rosl/web/`` (nothing is fetched from the
internet). A thread per connection (``ThreadingHTTPServer``) is fine for the few browsers that
look at one robot; their number is bounded.
"""

from __future__ import annotations

import errno
import json
import socket
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosl.introspection.errors import IntrospectionError
from rosl.introspection.viz import MARKERS, ODOMETRY, VizBuilder, subscribe_drawable

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.graph.cache import GraphCache
    from rosl.introspection.graph_view import GraphModel
    from rosl.introspection.session import Session
    from rosl.node.node import Node

WEB = Path(__file__).resolve().parent.parent / "web"
STATIC = {  # URL path -> (file in rosl/web/, content type)
    "/": ("index.html", "text/html; charset=utf-8"),
    "/index.html": ("index.html", "text/html; charset=utf-8"),
    "/viz.js": ("viz.js", "text/javascript; charset=utf-8"),
    "/viz.css": ("viz.css", "text/css; charset=utf-8"),
}
JSON_TYPE = "application/json"
INITIAL = b'<script id="initial" type="application/json">null</script>'  # in index.html
STATE_PERIOD_S = 0.2  # world snapshots: 5 per second at most
KEEPALIVE_S = 10.0  # a comment on an idle event stream, so a gone browser is noticed
MAX_STREAMS = 16  # event streams served at once (one thread each)
PATH_POINTS = 300  # most points of one odometry path in a snapshot
KEPT_POSES = 2000  # poses kept per odometry topic; past that, every other one is dropped
TITLE = "live"


class Hub:
    """The latest snapshot of each kind (``state``, ``graph``), versioned, for many readers."""

    def __init__(self) -> None:
        self._changed = threading.Condition()
        self._latest: dict[str, tuple[int, bytes]] = {}
        self._closed = False
        self._streams = 0  # event streams open now

    def publish(self, kind: str, payload: bytes) -> None:
        """Make ``payload`` the latest ``kind`` (unchanged payloads are not sent again)."""
        with self._changed:
            version, last = self._latest.get(kind, (0, b""))
            if payload != last:
                self._latest[kind] = (version + 1, payload)
                self._changed.notify_all()

    def latest(self, kind: str) -> bytes | None:
        """The latest payload of ``kind``, None before the first."""
        with self._changed:
            found = self._latest.get(kind)
            return None if found is None else found[1]

    def wait(self, seen: dict[str, int], timeout: float) -> list[tuple[str, int, bytes]] | None:
        """Payloads newer than the versions in ``seen`` (empty at the timeout; None once closed)."""

        def news() -> list[tuple[str, int, bytes]]:
            return [(k, v, p) for k, (v, p) in sorted(self._latest.items()) if seen.get(k) != v]

        with self._changed:
            self._changed.wait_for(lambda: self._closed or bool(news()), timeout)
            return None if self._closed else news()

    def open_stream(self) -> bool:
        """Count one more event stream; False when :data:`MAX_STREAMS` are open already."""
        with self._changed:
            if self._streams >= MAX_STREAMS:
                return False
            self._streams += 1
            return True

    def close_stream(self) -> None:
        """Count one event stream less."""
        with self._changed:
            self._streams -= 1

    def close(self) -> None:
        """End every event stream."""
        with self._changed:
            self._closed = True
            self._changed.notify_all()


# --- what is sent -----------------------------------------------------------------------------


def _r(value: float) -> float:
    return round(float(value), 3)


def _pts(points: list[tuple[float, float]]) -> list[list[float]]:
    return [[_r(x), _r(y)] for x, y in points]


def decimate(points: list[tuple[float, float]], limit: int) -> list[tuple[float, float]]:
    """At most ``limit`` points, evenly taken, the first and the last always kept."""
    if len(points) <= limit:
        return points
    step = (len(points) - 1) / (limit - 1)
    return [points[round(i * step)] for i in range(limit)]


def state_json(builder: VizBuilder, title: str = TITLE) -> dict[str, Any]:
    """The world as the page draws it: :meth:`VizBuilder.scene`, in plain JSON values.

    ``robots`` holds each odometry topic's pose; ``error`` says why nothing is drawn yet.
    """
    try:
        scene = builder.scene(title)
    except IntrospectionError as err:
        return {"title": title, "frame": builder.fixed, "note": builder.note, "error": str(err)}
    poses = {f"{topic} pose": topic for topic in builder.paths}
    frames = [(name, origin, yaw) for name, origin, yaw in scene.frames]
    return {
        "title": title,
        "frame": scene.frame,
        "note": builder.note,
        "error": None,
        "stamp_ns": builder.last_ns,
        "bounds": [_r(v) for v in scene.bounds()],
        "polygons": [_pts(p) for p in scene.polygons],
        "segments": [_pts([a, b]) for a, b in scene.segments],
        "circles": [[_r(c[0]), _r(c[1]), _r(r)] for c, r in scene.circles],
        "paths": [{"topic": t, "points": _pts(decimate(p, PATH_POINTS))} for t, p in scene.paths],
        "footprints": [_pts(p) for p in scene.footprints],
        "scan": _pts(scene.scan),
        "frames": [{"name": n, "x": _r(o[0]), "y": _r(o[1]), "yaw": _r(y)} for n, o, y in frames],
        "robots": [
            {"topic": poses[n], "x": _r(o[0]), "y": _r(o[1]), "yaw": _r(y)}
            for n, o, y in frames
            if n in poses
        ],
    }


def graph_json(model: GraphModel) -> dict[str, Any]:
    """``rosl graph``'s model: nodes (with how many share a name) and channels."""
    return {
        "nodes": [{"name": name, "count": count} for name, count in model.nodes.items()],
        "channels": [
            {
                "name": c.name, "kind": c.kind, "types": list(c.types), "sources": list(c.sources),
                "sinks": list(c.sinks), "marks": list(c.marks),
            }
            for c in model.channels
        ],
    }  # fmt: skip


def initial_script(hub: Hub) -> bytes:
    """index.html's ``#initial`` element holding the latest snapshots (JSON, safe in a script)."""
    state, graph = hub.latest("state"), hub.latest("graph")
    both = b'{"state":%s,"graph":%s}' % (state or b"null", graph or b"null")
    # "<" occurs only inside JSON strings, where \u003c means the same and cannot end the script
    return INITIAL.replace(b">null<", b">" + both.replace(b"<", b"\\u003c") + b"<")


def encode(value: dict[str, Any]) -> bytes:
    """Compact JSON bytes."""
    return json.dumps(value, separators=(",", ":")).encode()


# --- the bus side -------------------------------------------------------------------------------


class Feed:
    """Subscribes a node to every drawable topic, also to those published later."""

    def __init__(self, node: Node, builder: VizBuilder) -> None:
        self.node = node
        self.builder = builder
        self.topics: set[str] = set()
        self._markers: dict[str, tuple[list[Any], list[Any]]] = {}

    def refresh(self, graph: GraphCache) -> None:
        """Subscribe to the drawable topics that have a publisher now."""
        subscribe_drawable(self.node, graph, self.topics, self._taker, depth=100)

    def _taker(self, topic: str, type_name: str) -> Callable[[Any], None]:
        return lambda message: self.take(topic, type_name, message)

    def take(self, topic: str, type_name: str, message: Any) -> None:
        """Give the builder one message; a long odometry path keeps every other pose."""
        stamp = getattr(getattr(message, "header", None), "stamp", None)
        t_ns = stamp.sec * 1_000_000_000 + stamp.nanosec if stamp is not None else time.time_ns()
        if type_name == MARKERS:
            self._world(topic, message, t_ns)
            return
        self.builder.add(topic, type_name, message, t_ns)
        poses = self.builder.paths.get(topic)
        if type_name == ODOMETRY and poses is not None and len(poses) > KEPT_POSES:
            self.builder.paths[topic] = poses[::2]

    def _world(self, topic: str, message: Any, t_ns: int) -> None:
        """A topic's newest MarkerArray replaces what that topic drew before (a restarted sim)."""
        builder = self.builder
        builder.segments, builder.circles = [], []
        builder.add(topic, MARKERS, message, t_ns)
        self._markers[topic] = (builder.segments, builder.circles)
        builder.segments = [s for segments, _ in self._markers.values() for s in segments]
        builder.circles = [c for _, circles in self._markers.values() for c in circles]


# --- the web side -------------------------------------------------------------------------------


class LiveServer(ThreadingHTTPServer):
    """The page's HTTP server: static files, JSON snapshots and the event stream."""

    daemon_threads = True

    def __init__(self, address: str, port: int, hub: Hub) -> None:
        self.address_family = socket.AF_INET6 if ":" in address else socket.AF_INET
        self.hub = hub
        super().__init__((address, port), _Handler)

    @property
    def url(self) -> str:
        """The page's address."""
        host, port = self.server_address[:2]
        name = host.decode() if isinstance(host, bytes) else host
        shown = f"[{name}]" if ":" in name else name
        return f"http://{shown}:{port}/"


def open_server(address: str, port: int, hub: Hub) -> LiveServer:
    """Listen on ``address:port`` (port 0: any free one); serving starts in a thread.

    Raises:
        IntrospectionError: the port is in use, or the address is not one of this machine's.
    """
    where = f"{address}:{port}"
    try:
        server = LiveServer(address, port, hub)
    except socket.gaierror:
        raise IntrospectionError(f"cannot serve on {where}: unknown address '{address}'") from None
    except OverflowError:
        raise IntrospectionError(f"cannot serve on {where}: ports go from 0 to 65535") from None
    except OSError as err:
        reasons = {
            errno.EADDRINUSE: "the port is in use (pick another with --port)",
            errno.EADDRNOTAVAIL: f"'{address}' is not an address of this machine",
            errno.EACCES: "permission denied (ports below 1024 need privileges)",
        }
        reason = reasons.get(err.errno or 0, (err.strerror or str(err)).lower())
        raise IntrospectionError(f"cannot serve on {where}: {reason}") from None
    threading.Thread(target=server.serve_forever, name="rosl-viz-serve", daemon=True).start()
    return server


class _Handler(BaseHTTPRequestHandler):
    server: LiveServer
    timeout = 30.0  # a connection that sends no request is dropped

    def log_message(self, format: str, *args: Any) -> None:
        """Stay quiet: one line per request would bury the URL line."""

    def do_GET(self) -> None:
        """Serve a file of the page, a snapshot (``/state.json``, ``/graph.json``) or events."""
        path = self.path.split("?", 1)[0].split("#", 1)[0]
        if path in STATIC:
            name, kind = STATIC[path]
            body = (WEB / name).read_bytes()
            if name == "index.html":  # the page draws at once, before the first event
                body = body.replace(INITIAL, initial_script(self.server.hub), 1)
            self._send(200, kind, body)
        elif path in ("/state.json", "/graph.json"):
            payload = self.server.hub.latest(path[1:].removesuffix(".json"))
            self._send(200, JSON_TYPE, payload if payload is not None else b"null")
        elif path == "/events":
            self._events()
        else:
            self._send(404, "text/plain; charset=utf-8", f"no such page: {path}\n".encode())

    def _send(self, code: int, kind: str, body: bytes) -> None:
        self.send_response(code)
        self.send_header("Content-Type", kind)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        self.wfile.write(body)

    def _events(self) -> None:
        hub = self.server.hub
        if not hub.open_stream():
            self._send(503, "text/plain; charset=utf-8", b"too many live views open\n")
            return
        try:
            self.send_response(200)
            self.send_header("Content-Type", "text/event-stream")
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(b"retry: 1000\n\n")
            seen: dict[str, int] = {}
            while (news := hub.wait(seen, KEEPALIVE_S)) is not None:
                for kind, version, payload in news:
                    seen[kind] = version
                    self.wfile.write(b"event: %s\ndata: %s\n\n" % (kind.encode(), payload))
                if not news:
                    self.wfile.write(b": still here\n\n")
        except OSError:  # the browser went away (reset, broken pipe or a write timeout)
            pass
        finally:
            hub.close_stream()


# --- the loop -----------------------------------------------------------------------------------


def serve(
    session: Session,
    fixed_frame: str | None,
    address: str,
    port: int,
    started: Callable[[str], None],
) -> None:
    """Serve the live view until Ctrl-C (or the context's shutdown); ``started(url)`` once up.

    Raises:
        IntrospectionError: the address or port cannot be listened on.
    """
    import rosl
    from rosl.introspection.graph_view import GraphOptions, build

    hub = Hub()
    server = open_server(address, port, hub)  # before touching the bus: a bad port fails fast
    try:
        builder = VizBuilder(fixed_frame)
        feed = Feed(session.node(), builder)
        graph = session.graph(fresh=True)
        executor = rosl.SingleThreadedExecutor()
        executor.add_node(feed.node)
        own, generation, count, next_state = session.participant.sender, -1, -1, 0.0
        announced = False
        while rosl.ok():
            if graph.generation != generation:
                generation = graph.generation
                feed.refresh(graph)
                hub.publish("graph", encode(graph_json(build(graph, GraphOptions(), own))))
            if builder.count != count and time.monotonic() >= next_state:
                count, next_state = builder.count, time.monotonic() + STATE_PERIOD_S
                hub.publish("state", encode(state_json(builder)))
            if not announced:  # once the page has something to show
                started(server.url)
                announced = True
            executor.spin_once(timeout_sec=0.05)
    finally:
        hub.close()
        server.shutdown()
        server.server_close()
