"""World and robot files (YAML, ``format: rosl-world/1`` / ``rosl-robot/1``), validated.

Every problem is one line naming the file, the line, and what is expected: unknown keys,
wrong types, negative sizes, unknown robot models, robots spawned inside walls or on top of
each other. Geometry is in metres and radians, poses are ``[x, y, yaw]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from rosl.sim.errors import WorldFileError

WORLD_FORMAT = "rosl-world/1"
ROBOT_FORMAT = "rosl-robot/1"
_LINES = "__lines__"
_LINE = "__line__"

Point = tuple[float, float]


class _Loader(yaml.SafeLoader):
    """Remembers the line of every mapping and of each of its keys."""


def _mapping(loader: _Loader, node: yaml.MappingNode) -> dict[str, Any]:
    mapping = loader.construct_mapping(node, deep=True)
    mapping[_LINE] = node.start_mark.line + 1
    mapping[_LINES] = {k.value: k.start_mark.line + 1 for k, _ in node.value}
    return mapping


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping)


@dataclass(frozen=True, slots=True)
class Circle:
    """A circle obstacle (static or a dynamic body's shape)."""

    name: str
    center: Point
    radius: float


@dataclass(frozen=True, slots=True)
class Polygon:
    """A convex polygon obstacle (counter-clockwise points)."""

    name: str
    points: tuple[Point, ...]


@dataclass(frozen=True, slots=True)
class Segment:
    """A thin wall: a segment with a radius."""

    name: str
    a: Point
    b: Point
    radius: float = 0.01


Shape = Circle | Polygon | Segment


@dataclass(frozen=True, slots=True)
class DynamicBody:
    """A movable body: its shape, mass, and whether it is kinematic (moved by code)."""

    shape: Shape
    mass: float
    kinematic: bool


@dataclass(frozen=True, slots=True)
class Lidar:
    """A 2D laser scanner (Gazebo's ray sensor conventions)."""

    name: str
    frame_id: str
    topic: str
    rate: float
    samples: int
    angle_min: float
    angle_max: float
    range_min: float
    range_max: float
    noise_stddev: float = 0.0
    xy: Point = (0.0, 0.0)  # mount position in the robot frame (from frames when absent)


@dataclass(frozen=True, slots=True)
class Frame:
    """A fixed frame of the robot (published once on /tf_static)."""

    name: str
    parent: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)
    joint: str | None = None  # a wheel: turns about its z axis with this joint (on /tf)


@dataclass(frozen=True, slots=True)
class RobotModel:
    """A robot model: footprint, drive, frames and sensors."""

    name: str
    footprint: Circle | Polygon
    mass: float
    wheel_separation: float
    wheel_radius: float
    max_linear: float
    max_angular: float
    max_linear_accel: float
    cmd_vel: str
    odom_topic: str
    odom_frame: str
    base_frame: str
    odom_rate: float
    joint_states_topic: str | None
    joint_states_rate: float
    joints: tuple[str, ...]
    frames: tuple[Frame, ...]
    lidars: tuple[Lidar, ...]
    path: Path | None = None


@dataclass(frozen=True, slots=True)
class RobotSpec:
    """A robot placed in a world."""

    name: str
    model: RobotModel
    pose: tuple[float, float, float]
    namespace: str


@dataclass(frozen=True, slots=True)
class World:
    """A parsed world file."""

    name: str
    path: Path | None
    step_ns: int
    iterations: int
    seed: int
    statics: tuple[Shape, ...]
    dynamics: tuple[DynamicBody, ...]
    robots: tuple[RobotSpec, ...]
    extra: dict[str, Any] = field(default_factory=dict)


class _Reader:
    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, line: int, message: str) -> WorldFileError:
        return WorldFileError(f"{self.path}:{line}: {message}")

    def load(self) -> dict[str, Any]:
        try:
            data = yaml.load(self.path.read_text(encoding="utf-8"), Loader=_Loader)
        except yaml.YAMLError as err:
            mark = getattr(err, "problem_mark", None)
            line = mark.line + 1 if mark is not None else 0
            raise WorldFileError(
                f"{self.path}:{line}: not valid YAML: {getattr(err, 'problem', err)}"
            ) from None
        except OSError as err:
            raise WorldFileError(f"{self.path}: cannot read: {err.strerror}") from None
        if not isinstance(data, dict):
            raise self.fail(1, "expected a mapping with 'format:' at the top")
        return data

    def keys(self, entry: dict[str, Any], allowed: set[str], required: set[str], what: str) -> None:
        line = entry.get(_LINE, 0)
        for key in entry:
            if key in (_LINE, _LINES):
                continue
            if key not in allowed:
                from rosl.idl.names import did_you_mean

                hint = did_you_mean(key, allowed)
                raise self.fail(
                    self.line_of(entry, key),
                    f"unknown key '{key}' in {what}{hint} (expected: {', '.join(sorted(allowed))})",
                )
        for key in sorted(required):
            if key not in entry:
                raise self.fail(line, f"{what} needs '{key}:'")

    @staticmethod
    def line_of(entry: dict[str, Any], key: str) -> int:
        return int(entry.get(_LINES, {}).get(key, entry.get(_LINE, 0)))

    def number(
        self,
        entry: dict[str, Any],
        key: str,
        *,
        default: float | None = None,
        positive: bool = False,
        minimum: float | None = None,
    ) -> float:
        if key not in entry:
            if default is None:
                raise self.fail(entry.get(_LINE, 0), f"missing '{key}:' (a number)")
            return default
        value = entry[key]
        if (
            isinstance(value, bool)
            or not isinstance(value, (int, float))
            or not math.isfinite(value)
        ):
            raise self.fail(self.line_of(entry, key), f"'{key}' must be a number, not {value!r}")
        if positive and value <= 0:
            raise self.fail(
                self.line_of(entry, key), f"'{key}' must be greater than 0, not {value}"
            )
        if minimum is not None and value < minimum:
            raise self.fail(
                self.line_of(entry, key), f"'{key}' must be at least {minimum}, not {value}"
            )
        return float(value)

    def point(self, entry: dict[str, Any], key: str, size: int = 2) -> tuple[float, ...]:
        value = entry.get(key)
        if (
            not isinstance(value, list)
            or len(value) != size
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        ):
            shape = "[x, y]" if size == 2 else "[x, y, yaw]" if size == 3 else f"{size} numbers"
            raise self.fail(self.line_of(entry, key), f"'{key}' must be {shape}, not {value!r}")
        return tuple(float(v) for v in value)

    def text(self, entry: dict[str, Any], key: str, default: str | None = None) -> str:
        value = entry.get(key, default)
        if not isinstance(value, str):
            raise self.fail(self.line_of(entry, key), f"'{key}' must be text, not {value!r}")
        return value

    def points(self, entry: dict[str, Any], key: str, minimum: int) -> list[Point]:
        value = entry.get(key)
        line = self.line_of(entry, key)
        if not isinstance(value, list) or len(value) < minimum:
            raise self.fail(line, f"'{key}' must be a list of at least {minimum} [x, y] points")
        out = []
        for item in value:
            if (
                not isinstance(item, list)
                or len(item) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in item)
            ):
                raise self.fail(line, f"each of '{key}' must be [x, y], not {item!r}")
            out.append((float(item[0]), float(item[1])))
        return out


# --- shapes ---------------------------------------------------------------------------------

_SHAPE_KEYS = {
    "cylinder": ({"type", "name", "center", "radius"}, {"center", "radius"}),
    "box": ({"type", "name", "center", "size", "yaw"}, {"center", "size"}),
    "segment": ({"type", "name", "points", "radius"}, {"points"}),
    "polygon": ({"type", "name", "points", "ring", "thickness"}, {"points"}),
    "regular_polygon": (
        {"type", "name", "center", "sides", "circumradius", "yaw"},
        {"center", "sides", "circumradius"},
    ),
    "grid": (
        {"type", "name", "shape", "origin", "step", "count"},
        {"shape", "origin", "step", "count"},
    ),
}
_DYNAMIC_KEYS = {"mass", "kinematic"}


def _box(center: Point, size: tuple[float, ...], yaw: float) -> list[Point]:
    hx, hy = size[0] / 2, size[1] / 2
    c, s = math.cos(yaw), math.sin(yaw)
    return [
        (center[0] + c * x - s * y, center[1] + s * x + c * y)
        for x, y in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy))
    ]


def _ccw(points: list[Point]) -> list[Point]:
    area = sum(
        a[0] * b[1] - b[0] * a[1] for a, b in zip(points, points[1:] + points[:1], strict=True)
    )
    return points if area > 0 else points[::-1]


def _shapes(reader: _Reader, entry: Any, extra: set[str] = frozenset()) -> list[Shape]:
    if not isinstance(entry, dict) or "type" not in entry:
        line = entry.get(_LINE, 0) if isinstance(entry, dict) else 0
        raise reader.fail(line, f"each shape needs 'type:' ({', '.join(_SHAPE_KEYS)})")
    kind = entry["type"]
    if kind not in _SHAPE_KEYS:
        raise reader.fail(
            reader.line_of(entry, "type"),
            f"unknown shape type '{kind}' (expected: {', '.join(_SHAPE_KEYS)})",
        )
    allowed, required = _SHAPE_KEYS[kind]
    reader.keys(entry, allowed | extra, required, f"a {kind}")
    name = str(entry.get("name", kind))
    if kind == "cylinder":
        return [
            Circle(
                name, reader.point(entry, "center"), reader.number(entry, "radius", positive=True)
            )
        ]  # type: ignore[arg-type]
    if kind == "box":
        size = reader.point(entry, "size")
        if min(size) <= 0:
            raise reader.fail(
                reader.line_of(entry, "size"), f"'size' must be positive, not {list(size)}"
            )
        return [
            Polygon(
                name,
                tuple(
                    _box(
                        reader.point(entry, "center"),
                        size,
                        reader.number(entry, "yaw", default=0.0),
                    )
                ),
            )
        ]  # type: ignore[arg-type]
    if kind == "segment":
        a, b = reader.points(entry, "points", 2)[:2]
        return [Segment(name, a, b, reader.number(entry, "radius", default=0.01, positive=True))]
    if kind == "regular_polygon":
        center = reader.point(entry, "center")
        sides = int(reader.number(entry, "sides", minimum=3))
        radius = reader.number(entry, "circumradius", positive=True)
        yaw = reader.number(entry, "yaw", default=0.0)
        points = [
            (
                center[0] + radius * math.cos(yaw + 2 * math.pi * i / sides),
                center[1] + radius * math.sin(yaw + 2 * math.pi * i / sides),
            )
            for i in range(sides)
        ]
        return [Polygon(name, tuple(points))]
    if kind == "polygon":
        points = reader.points(entry, "points", 3)
        if not entry.get("ring"):
            return [Polygon(name, tuple(_ccw(points)))]
        thickness = reader.number(entry, "thickness", positive=True)
        return _ring(name, _ccw(points), thickness)
    # grid
    shape = entry["shape"]
    origin = reader.point(entry, "origin")
    step = reader.point(entry, "step")
    count = reader.point(entry, "count")
    out: list[Shape] = []
    for i in range(int(count[0])):
        for j in range(int(count[1])):
            item = dict(shape)
            item["center"] = [origin[0] + i * step[0], origin[1] + j * step[1]]
            item.setdefault("name", f"{name}_{i}_{j}")
            item[_LINES] = {**shape.get(_LINES, {}), "center": reader.line_of(entry, "origin")}
            out += _shapes(reader, item)
    return out


def _ring(name: str, inner: list[Point], thickness: float) -> list[Shape]:
    """A closed wall whose inner face is ``inner``: one quadrilateral per side, outward."""
    n = len(inner)
    normals = []
    for k in range(n):
        (x1, y1), (x2, y2) = inner[k], inner[(k + 1) % n]
        length = math.hypot(x2 - x1, y2 - y1)
        normals.append(((y2 - y1) / length, -(x2 - x1) / length))  # outward for a ccw polygon
    outer = []
    for k in range(n):
        n1, n2 = normals[k - 1], normals[k]
        bx, by = n1[0] + n2[0], n1[1] + n2[1]
        scale = thickness / max(1e-9, (bx * n2[0] + by * n2[1]))
        outer.append((inner[k][0] + bx * scale, inner[k][1] + by * scale))
    return [
        Polygon(f"{name}_{k}", (inner[k], outer[k], outer[(k + 1) % n], inner[(k + 1) % n])[::-1])
        for k in range(n)
    ]


# --- robots ---------------------------------------------------------------------------------


def _robot_model(name: str, world_path: Path | None, line: int, where: str) -> RobotModel:
    from rosl.resources import shipped_dir

    candidates = []
    if world_path is not None:
        candidates.append(world_path.parent / "robots" / f"{name}.yaml")
    candidates.append(shipped_dir("worlds") / "robots" / f"{name}.yaml")
    for path in candidates:
        if path.is_file():
            return load_robot(path)
    known = sorted({p.stem for c in candidates for p in c.parent.glob("*.yaml")})
    raise WorldFileError(
        f"{where}:{line}: robot model '{name}' not found (known: {', '.join(known)})"
    )


def load_robot(path: Path) -> RobotModel:
    """Read a robot model file."""
    reader = _Reader(path)
    data = reader.load()
    reader.keys(
        data,
        {"format", "name", "footprint", "mass", "drive", "frames", "sensors"},
        {"format", "footprint", "drive"},
        "a robot file",
    )
    if data["format"] != ROBOT_FORMAT:
        raise reader.fail(
            reader.line_of(data, "format"),
            f"format must be '{ROBOT_FORMAT}', not {data['format']!r}",
        )
    foot = data["footprint"]
    if foot.get("type") == "circle":
        reader.keys(foot, {"type", "radius"}, {"radius"}, "a circle footprint")
        footprint: Circle | Polygon = Circle(
            "footprint", (0.0, 0.0), reader.number(foot, "radius", positive=True)
        )
    elif foot.get("type") == "box":
        reader.keys(foot, {"type", "size", "offset"}, {"size"}, "a box footprint")
        offset = reader.point(foot, "offset") if "offset" in foot else (0.0, 0.0)
        footprint = Polygon("footprint", tuple(_box(offset, reader.point(foot, "size"), 0.0)))  # type: ignore[arg-type]
    else:
        raise reader.fail(foot.get(_LINE, 0), "footprint type must be 'circle' or 'box'")
    drive = data["drive"]
    reader.keys(
        drive,
        {
            "wheel_separation",
            "wheel_radius",
            "max_linear",
            "max_angular",
            "max_linear_accel",
            "cmd_vel",
            "odom",
            "joint_states",
        },
        {"wheel_separation", "wheel_radius"},
        "drive",
    )
    odom = drive.get("odom", {})
    joints_entry = drive.get("joint_states")
    frames = []
    for frame_name, frame in (data.get("frames") or {}).items():
        if frame_name in (_LINE, _LINES):
            continue
        reader.keys(
            frame, {"parent", "xyz", "rpy", "joint"}, {"parent", "xyz"}, f"frame '{frame_name}'"
        )
        frames.append(
            Frame(
                frame_name,
                reader.text(frame, "parent"),
                reader.point(frame, "xyz", 3),  # type: ignore[arg-type]
                reader.point(frame, "rpy", 3) if "rpy" in frame else (0.0, 0.0, 0.0),  # type: ignore[arg-type]
                reader.text(frame, "joint") if "joint" in frame else None,
            )
        )
    lidars = []
    for sensor in data.get("sensors") or []:
        reader.keys(
            sensor,
            {
                "type",
                "name",
                "frame_id",
                "topic",
                "rate",
                "samples",
                "angle_min",
                "angle_max",
                "range_min",
                "range_max",
                "noise_stddev",
                "xy",
            },
            {
                "type",
                "frame_id",
                "topic",
                "rate",
                "samples",
                "angle_min",
                "angle_max",
                "range_min",
                "range_max",
            },
            "a sensor",
        )
        if sensor["type"] != "lidar2d":
            raise reader.fail(reader.line_of(sensor, "type"), "sensor type must be 'lidar2d'")
        frame_id = reader.text(sensor, "frame_id")
        xy = reader.point(sensor, "xy") if "xy" in sensor else _frame_xy(frames, frame_id)
        lidars.append(
            Lidar(
                str(sensor.get("name", "lidar")),
                frame_id,
                reader.text(sensor, "topic"),
                reader.number(sensor, "rate", positive=True),
                int(reader.number(sensor, "samples", minimum=1)),
                reader.number(sensor, "angle_min"),
                reader.number(sensor, "angle_max"),
                reader.number(sensor, "range_min", minimum=0.0),
                reader.number(sensor, "range_max", positive=True),
                reader.number(sensor, "noise_stddev", default=0.0, minimum=0.0),
                xy,  # type: ignore[arg-type]
            )
        )
    return RobotModel(
        name=str(data.get("name", path.stem)),
        footprint=footprint,
        mass=reader.number(data, "mass", default=1.0, positive=True),
        wheel_separation=reader.number(drive, "wheel_separation", positive=True),
        wheel_radius=reader.number(drive, "wheel_radius", positive=True),
        max_linear=reader.number(drive, "max_linear", default=1.0, positive=True),
        max_angular=reader.number(drive, "max_angular", default=2.0, positive=True),
        max_linear_accel=reader.number(drive, "max_linear_accel", default=1.0, positive=True),
        cmd_vel=str(drive.get("cmd_vel", "cmd_vel")),
        odom_topic=str(odom.get("topic", "odom")),
        odom_frame=str(odom.get("frame_id", "odom")),
        base_frame=str(odom.get("child_frame_id", "base_footprint")),
        odom_rate=float(odom.get("rate", 30)),
        joint_states_topic=str(joints_entry["topic"]) if joints_entry else None,
        joint_states_rate=float(joints_entry.get("rate", 30)) if joints_entry else 0.0,
        joints=tuple(joints_entry.get("joints", [])) if joints_entry else (),
        frames=tuple(frames),
        lidars=tuple(lidars),
        path=path,
    )


def _frame_xy(frames: list[Frame], name: str) -> Point:
    """A frame's x, y relative to the robot's base, walking up its parents."""
    by_name = {f.name: f for f in frames}
    x = y = 0.0
    while name in by_name:
        frame = by_name[name]
        x += frame.xyz[0]
        y += frame.xyz[1]
        name = frame.parent
    return (x, y)


# --- worlds ---------------------------------------------------------------------------------


def load_world(path: Path) -> World:
    """Read and validate a world file (and its robots' model files).

    Raises:
        WorldFileError: with file:line and what is expected.
    """
    reader = _Reader(path)
    data = reader.load()
    reader.keys(
        data,
        {"format", "name", "physics", "seed", "static", "dynamic", "robots"},
        {"format"},
        "a world file",
    )
    if data["format"] != WORLD_FORMAT:
        raise reader.fail(
            reader.line_of(data, "format"),
            f"format must be '{WORLD_FORMAT}', not {data['format']!r}",
        )
    physics = data.get("physics") or {_LINE: reader.line_of(data, "format")}
    reader.keys(physics, {"step", "iterations"}, set(), "physics")
    step = reader.number(physics, "step", default=0.01, positive=True)
    seed = data.get("seed", 0)
    if not isinstance(seed, int) or isinstance(seed, bool):
        raise reader.fail(
            reader.line_of(data, "seed"), f"'seed' must be a whole number, not {seed!r}"
        )
    statics: list[Shape] = []
    for entry in data.get("static") or []:
        statics += _shapes(reader, entry)
    dynamics = []
    for entry in data.get("dynamic") or []:
        for shape in _shapes(reader, entry, _DYNAMIC_KEYS):
            dynamics.append(
                DynamicBody(
                    shape,
                    reader.number(entry, "mass", default=1.0, positive=True),
                    bool(entry.get("kinematic", False)),
                )
            )
    robots = []
    for entry in data.get("robots") or []:
        reader.keys(entry, {"name", "model", "pose", "namespace"}, {"model", "pose"}, "a robot")
        model = _robot_model(
            reader.text(entry, "model"), path, reader.line_of(entry, "model"), str(path)
        )
        pose = reader.point(entry, "pose", 3)
        namespace = str(entry.get("namespace", "") or "").strip("/")
        robots.append(RobotSpec(str(entry.get("name", model.name)), model, pose, namespace))  # type: ignore[arg-type]
    world = World(
        str(data.get("name", path.stem)),
        path,
        round(step * 1e9),
        int(reader.number(physics, "iterations", default=10, minimum=1)),
        seed,
        tuple(statics),
        tuple(dynamics),
        tuple(robots),
    )
    _check_spawns(reader, data, world)
    return world


def _check_spawns(reader: _Reader, data: dict[str, Any], world: World) -> None:
    from rosl.sim.world import footprint_overlaps

    entries = data.get("robots") or []
    for index, robot in enumerate(world.robots):
        line = reader.line_of(entries[index], "pose")
        hit = footprint_overlaps(robot, world.statics)
        if hit is not None:
            raise reader.fail(
                line, f"robot '{robot.name}' is spawned inside '{hit}'; move its pose"
            )
        for other in world.robots[:index]:
            dx, dy = robot.pose[0] - other.pose[0], robot.pose[1] - other.pose[1]
            if math.hypot(dx, dy) < _reach(robot) + _reach(other):
                raise reader.fail(
                    line, f"robot '{robot.name}' overlaps robot '{other.name}' at spawn"
                )


def _reach(robot: RobotSpec) -> float:
    foot = robot.model.footprint
    if isinstance(foot, Circle):
        return foot.radius
    return max(math.hypot(x, y) for x, y in foot.points)


def resolve_world(name: str) -> Path:
    """A world file path from a path, a file name in the shipped worlds, or a bare name."""
    from rosl.resources import shipped_dir

    path = Path(name)
    if path.is_file():
        return path
    shipped = shipped_dir("worlds")
    for candidate in (shipped / name, shipped / f"{name}.yaml", shipped / path.name):
        if candidate.is_file():
            return candidate
    known = sorted(p.name for p in shipped.glob("*.yaml"))
    raise WorldFileError(f"world '{name}' not found (shipped worlds: {', '.join(known)})")
