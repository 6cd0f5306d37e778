"""``rosl viz``: a picture instead of RViz, from a recorded bag or from the live bus.

Messages are taken in time order: ``/tf`` and ``/tf_static`` fill a TF buffer, odometry
messages add to each robot's path, the world's markers (``/world_markers``) give the
obstacles, and each LaserScan is placed with the TF known at its time (the last one is drawn).
Everything is then expressed in the fixed frame and drawn by :mod:`rosl.sim.render`. The
fixed frame is ``odom`` by default, as the tutorial sets RViz; when the TF tree has no ``odom``
(Dolly's odometry is in ``odom_demo``), the frame the odometry is given in is taken instead,
and :attr:`VizBuilder.note` says which.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any

from rosl.introspection.errors import IntrospectionError
from rosl.introspection.tf import TfBuffer
from rosl.sim.render import Scene, footprint_points, write
from rosl.tf2.transform import Transform

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from rosl.graph.cache import GraphCache
    from rosl.introspection.session import Session
    from rosl.node.node import Node

ODOMETRY = "nav_msgs/msg/Odometry"
SCAN = "sensor_msgs/msg/LaserScan"
TF = "tf2_msgs/msg/TFMessage"
MARKERS = "visualization_msgs/msg/MarkerArray"
STRING = "std_msgs/msg/String"
KINDS = (ODOMETRY, SCAN, TF, MARKERS, STRING)
DEFAULT_FRAME = "odom"
Point = tuple[float, float]


def _transform_of(pose: Any) -> Transform:
    p, q = pose.position, pose.orientation
    return Transform((p.x, p.y, p.z), (q.x, q.y, q.z, q.w))


def _yaw(transform: Transform) -> float:
    return transform.rpy()[2]


class VizBuilder:
    """Collects messages (in time order) and turns them into a :class:`Scene`."""

    def __init__(self, fixed_frame: str | None = None) -> None:
        self.requested = fixed_frame  # None: odom, or the odometry's frame when there is no odom
        self.fixed = fixed_frame or DEFAULT_FRAME
        self.note: str | None = None  # how the fixed frame was chosen, when not as asked
        self.tf = TfBuffer()
        self.paths: dict[str, list[tuple[str, float, float]]] = {}  # topic -> (frame, x, y)
        self.last_pose: dict[str, tuple[str, Transform]] = {}
        self.scan_points: list[Point] = []
        self.scan_frame: tuple[str, Transform] | None = None
        self.segments: list[tuple[str, Point, Point]] = []
        self.circles: list[tuple[str, Point, float]] = []
        self.last_ns = 0
        self.count = 0
        self.footprint: Any = None  # from a robot_description's base link geometry

    def add(self, topic: str, type_name: str, message: Any, t_ns: int) -> None:
        """Take one message received (or recorded) at ``t_ns``."""
        self.count += 1
        self.last_ns = max(self.last_ns, t_ns)
        if type_name == TF:
            self.tf.add(message, topic == "/tf_static", (0, 0), t_ns)
        elif type_name == ODOMETRY:
            frame = message.header.frame_id.lstrip("/")
            pose = _transform_of(message.pose.pose)
            self.paths.setdefault(topic, []).append((frame, pose.translation[0],
                                                     pose.translation[1]))  # fmt: skip
            self.last_pose[topic] = (frame, pose)
        elif type_name == SCAN:
            self._scan(message)
        elif type_name == MARKERS:
            self._markers(message)
        elif type_name == STRING and topic.endswith("robot_description"):
            self.footprint = _footprint(message.data)

    def _to_fixed(self, frame: str) -> Transform | None:
        if frame == self.fixed:
            return Transform()
        try:
            transform, _ = self.tf.lookup(self.fixed, frame)
        except IntrospectionError:
            return None
        return transform

    def _scan(self, message: Any) -> None:
        frame = message.header.frame_id.lstrip("/")
        self.choose_fixed_frame()
        where = self._to_fixed(frame)
        if where is None:
            return
        points = []
        for index, distance in enumerate(message.ranges):
            if math.isfinite(distance) and distance > 0:
                angle = message.angle_min + index * message.angle_increment
                local = Transform((distance * math.cos(angle), distance * math.sin(angle), 0.0))
                points.append((where * local).translation[:2])
        self.scan_points = points
        self.scan_frame = (frame, where)

    def _markers(self, message: Any) -> None:
        for marker in message.markers:
            frame = marker.header.frame_id.lstrip("/")
            if marker.type == 5:  # LINE_LIST
                pts = [(p.x, p.y) for p in marker.points]
                for a, b in zip(pts[::2], pts[1::2], strict=False):
                    self.segments.append((frame, a, b))
            elif marker.type == 3:  # CYLINDER
                p = marker.pose.position
                self.circles.append((frame, (p.x, p.y), marker.scale.x / 2))

    def choose_fixed_frame(self) -> str:
        """The fixed frame: as asked, else ``odom``, else the frame odometry is given in.

        Without ``odom`` in the TF tree, the first odometry topic's frame (by topic name) that
        the tree knows is taken, and :attr:`note` says so and names the other candidates.
        Asked again as messages arrive, so each scan is placed in the frame known by then.
        """
        if self.requested is not None:
            return self.fixed
        self.fixed, self.note = DEFAULT_FRAME, None
        known = self.tf.frames()
        if DEFAULT_FRAME in known:
            return self.fixed
        candidates: dict[str, list[str]] = {}
        for topic in sorted(self.last_pose):
            frame = self.last_pose[topic][0]
            if frame and (not known or frame in known):
                candidates.setdefault(frame, []).append(topic)
        if not candidates or DEFAULT_FRAME in candidates:
            return self.fixed
        chosen, *others = candidates
        self.fixed = chosen
        note = (
            f"fixed frame: {chosen} (there is no '{DEFAULT_FRAME}' frame; {chosen} is the frame "
            f"of {', '.join(candidates[chosen])}"
        )
        if others:
            also = ", ".join(f"{frame} ({', '.join(candidates[frame])})" for frame in others)
            note += f"; other odometry frames: {also}; pick one with --fixed-frame"
        self.note = note + ")"
        return chosen

    def scene(self, title: str) -> Scene:
        """Everything collected, in the fixed frame (see :meth:`choose_fixed_frame`).

        Raises:
            IntrospectionError: nothing drawable arrived, or the fixed frame is unknown.
        """
        if not (self.paths or self.scan_points or self.segments or self.circles):
            raise IntrospectionError(
                "nothing to draw: no odometry, LaserScan or /world_markers messages "
                f"(read {self.count} messages)"
            )
        self.choose_fixed_frame()
        known = self.tf.frames()
        if known and self.fixed not in known:
            raise IntrospectionError(
                f"fixed frame '{self.fixed}' is not in the TF tree (frames: "
                f"{', '.join(sorted(known))}); choose one with --fixed-frame"
            )
        scene = Scene(title=title, frame=self.fixed)

        def place(frame: str, point: Point) -> Point | None:
            where = self._to_fixed(frame)
            if where is None:
                return None
            return (where * Transform((point[0], point[1], 0.0))).translation[:2]

        for frame, a, b in self.segments:
            pa, pb = place(frame, a), place(frame, b)
            if pa is not None and pb is not None:
                scene.segments.append((pa, pb))
        for frame, center, radius in self.circles:
            placed = place(frame, center)
            if placed is not None:
                scene.circles.append((placed, radius))
        for topic, poses in self.paths.items():
            points = [p for frame, x, y in poses if (p := place(frame, (x, y))) is not None]
            scene.paths.append((topic, points))
            frame, pose = self.last_pose[topic]
            where = self._to_fixed(frame)
            if where is not None:
                robot = where * pose
                x, y = robot.translation[:2]
                scene.frames.append((f"{topic} pose", (x, y), _yaw(robot)))
                if self.footprint is not None:
                    scene.footprints.append(footprint_points(self.footprint, (x, y, _yaw(robot))))
        scene.scan = list(self.scan_points)
        if self.scan_frame is not None:
            name, where = self.scan_frame
            scene.frames.append((name, where.translation[:2], _yaw(where)))
        scene.frames.append((self.fixed, (0.0, 0.0), 0.0))
        return scene


def rviz_fixed_frame(config: Path) -> str | None:
    """The Fixed Frame an RViz config file (``rviz2 -d FILE``) names; None if it names none.

    Raises:
        IntrospectionError: the file cannot be read or is not an RViz (YAML) config.
    """
    import yaml

    from rosl.introspection.errors import IntrospectionError

    try:
        data = yaml.safe_load(config.read_text(encoding="utf-8"))
    except OSError as err:
        raise IntrospectionError(f"{config}: cannot read: {err.strerror}") from None
    except (yaml.YAMLError, UnicodeDecodeError):
        raise IntrospectionError(f"{config}: not an RViz config (not YAML)") from None
    manager = data.get("Visualization Manager") if isinstance(data, dict) else None
    if not isinstance(manager, dict):
        raise IntrospectionError(f"{config}: not an RViz config (no 'Visualization Manager')")
    options = manager.get("Global Options")
    frame = options.get("Fixed Frame") if isinstance(options, dict) else None
    return str(frame) if frame else None


def from_bag(bag: Path, fixed_frame: str | None) -> VizBuilder:
    """Read the drawable topics of a bag (folder or .mcap file) in time order.

    ``fixed_frame`` None: ``odom``, or the odometry's own frame when there is no ``odom``.
    """
    from rosl.bag.reader import iter_bag
    from rosl.idl import registry

    builder = VizBuilder(fixed_frame)
    store = registry.store()
    for kind in KINDS:
        registry.get_message_class(kind)
    for message in iter_bag(bag):
        if message.type in KINDS:
            decoded = store.deserialize(message.data, message.type)
            builder.add(message.topic, message.type, decoded, message.log_time)
    return builder


def live(session: Session, fixed_frame: str | None, seconds: float) -> VizBuilder:
    """Listen to the drawable topics on the bus for ``seconds``.

    Late-joining is fine: /tf_static and /world_markers keep their history for new listeners.
    """
    import rosl

    builder = VizBuilder(fixed_frame)
    node = session.node()
    graph = session.graph(fresh=True)
    subscribed: set[str] = set()
    subscribe_drawable(
        node, graph, subscribed, lambda name, kind: _taker(builder, name, kind), depth=1000
    )
    if not subscribed:
        raise IntrospectionError(
            "nothing to draw on the bus: no node publishes odometry, LaserScan, TF or markers "
            "(start one, e.g. `rosl sim turtlebot3_world`)"
        )
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    deadline = time.monotonic() + seconds
    while (left := deadline - time.monotonic()) > 0 and rosl.ok():
        executor.spin_once(timeout_sec=min(left, 0.05))
    return builder


def subscribe_drawable(
    node: Node,
    graph: GraphCache,
    subscribed: set[str],
    callback: Callable[[str, str], Callable[[Any], None]],
    depth: int,
) -> None:
    """Subscribe ``node`` to every drawable topic with a publisher not in ``subscribed``.

    A transient-local publisher gets a transient-local subscription (its history arrives), a
    best-effort one a best-effort subscription (a reliable one would match nothing);
    ``callback(topic, type)`` makes each subscription's callback; ``subscribed`` grows.
    """
    from rosl.graph.records import PUBLISHER
    from rosl.idl.registry import get_message_class
    from rosl.node.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    for _, endpoint in graph.endpoints(PUBLISHER):
        if endpoint.type not in KINDS or endpoint.name in subscribed:
            continue
        subscribed.add(endpoint.name)
        latched = str(endpoint.qos.get("durability", "")).upper() == "TRANSIENT_LOCAL"
        durability = DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE
        best_effort = str(endpoint.qos.get("reliability", "")).upper() == "BEST_EFFORT"
        reliability = ReliabilityPolicy.BEST_EFFORT if best_effort else ReliabilityPolicy.RELIABLE
        qos = QoSProfile(depth=depth, durability=durability, reliability=reliability)
        subscription = node.create_subscription(
            get_message_class(endpoint.type), endpoint.name, callback(endpoint.name, endpoint.type),
            qos,
        )  # fmt: skip
        subscription.never_hold()  # a view never slows what it shows (see rosl.bus.shm_ring)


def _footprint(urdf: str) -> Any:
    """The footprint drawn in a rosl robot description (a cylinder or a box), if any."""
    import re

    from rosl.sim.worldfile import Circle, Polygon

    cylinder = re.search(r'<cylinder radius="([0-9.eE+-]+)"', urdf)
    if cylinder:
        return Circle("footprint", (0.0, 0.0), float(cylinder.group(1)))
    box = re.search(r'<box size="([0-9.eE+-]+) ([0-9.eE+-]+)', urdf)
    if box:
        hx, hy = float(box.group(1)) / 2, float(box.group(2)) / 2
        return Polygon("footprint", ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)))
    return None


def _taker(builder: VizBuilder, topic: str, type_name: str) -> Any:
    def take(message: Any) -> None:
        stamp = getattr(getattr(message, "header", None), "stamp", None)
        t_ns = stamp.sec * 1_000_000_000 + stamp.nanosec if stamp is not None else time.time_ns()
        builder.add(topic, type_name, message, t_ns)

    return take


def draw(builder: VizBuilder, output: Path, title: str) -> Path:
    """Write the picture (.svg or .png)."""
    if output.suffix.lower() not in (".svg", ".png"):
        raise IntrospectionError(f"-o {output}: the picture must be a .svg or .png file")
    return write(builder.scene(title), output)
