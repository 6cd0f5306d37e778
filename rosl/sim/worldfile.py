"""World and robot files (YAML, ``format: rosl-world/1`` / ``rosl-robot/1``), validated.

Every problem is one line naming the file, the line, and what is expected: unknown keys,
wrong types, negative sizes, unknown robot models, robots spawned inside walls or on top of
each other. Geometry is in metres and radians, poses are ``[x, y, yaw]``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rosl.sim.errors import WorldFileError
from rosl.sim.model import (
    Circle,
    DynamicBody,
    Frame,
    Lidar,
    Point,
    Polygon,
    RobotModel,
    RobotSpec,
    Segment,
    Shape,
    World,
    signed_area,
)
from rosl.sim.yaml_reader import LINE as _LINE
from rosl.sim.yaml_reader import LINES as _LINES
from rosl.sim.yaml_reader import YamlReader as _Reader

if TYPE_CHECKING:
    from collections.abc import Set as AbstractSet

__all__ = [  # the records live in model.py; importing them from here keeps working
    "ROBOT_FORMAT",
    "WORLD_FORMAT",
    "Circle",
    "DynamicBody",
    "Frame",
    "Lidar",
    "Point",
    "Polygon",
    "RobotModel",
    "RobotSpec",
    "Segment",
    "Shape",
    "World",
    "load_robot",
    "load_world",
    "resolve_world",
]

WORLD_FORMAT = "rosl-world/1"
ROBOT_FORMAT = "rosl-robot/1"


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
    return points if signed_area(points) > 0 else points[::-1]


def _shapes(
    reader: _Reader, item: Any, line: int, extra: AbstractSet[str] = frozenset()
) -> list[Shape]:
    entry = reader.item(line, item, "a shape with 'type:'")
    if "type" not in entry:
        raise reader.fail(entry[_LINE], f"each shape needs 'type:' ({', '.join(_SHAPE_KEYS)})")
    kind = entry["type"]
    if kind not in _SHAPE_KEYS:
        raise reader.fail(
            reader.line_of(entry, "type"),
            f"unknown shape type '{kind}' (expected: {', '.join(_SHAPE_KEYS)})",
        )
    allowed, required = _SHAPE_KEYS[kind]
    reader.keys(entry, allowed | extra, required, f"a {kind}")
    name = reader.text(entry, "name", kind)
    if kind == "cylinder":
        center = reader.point(entry, "center")
        return [Circle(name, center, reader.number(entry, "radius", positive=True))]
    if kind == "box":
        size = reader.point(entry, "size")
        if min(size) <= 0:
            raise reader.fail(
                reader.line_of(entry, "size"), f"'size' must be positive, not {list(size)}"
            )
        center = reader.point(entry, "center")
        yaw = reader.number(entry, "yaw", default=0.0)
        return [Polygon(name, tuple(_box(center, size, yaw)))]
    if kind == "segment":
        a, b = reader.points(entry, "points", 2)[:2]
        return [Segment(name, a, b, reader.number(entry, "radius", default=0.01, positive=True))]
    if kind == "regular_polygon":
        center = reader.point(entry, "center")
        sides = reader.integer(entry, "sides", minimum=3)
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
        _check_simple(reader, reader.line_of(entry, "points"), points)
        if not reader.flag(entry, "ring"):
            return [Polygon(name, tuple(_ccw(points)))]
        thickness = reader.number(entry, "thickness", positive=True)
        return _ring(name, _ccw(points), thickness)
    return _grid(reader, entry, name)


def _grid(reader: _Reader, entry: dict[str, Any], name: str) -> list[Shape]:
    """A shape repeated ``count`` times, ``step`` apart, from ``origin``."""
    shape = reader.mapping(entry, "shape", "the shape to repeat, without 'center:'")
    origin = reader.point(entry, "origin")
    step = reader.point(entry, "step")
    count = reader.point(entry, "count")
    if not all(c.is_integer() and c >= 1 for c in count):
        raise reader.fail(
            reader.line_of(entry, "count"),
            f"'count' must be two whole numbers of at least 1, not {list(count)}",
        )
    out: list[Shape] = []
    for i in range(int(count[0])):
        for j in range(int(count[1])):
            item = dict(shape)
            item["center"] = [origin[0] + i * step[0], origin[1] + j * step[1]]
            item.setdefault("name", f"{name}_{i}_{j}")
            item[_LINES] = {**shape.get(_LINES, {}), "center": reader.line_of(entry, "origin")}
            out += _shapes(reader, item, shape[_LINE])
    return out


def _check_simple(reader: _Reader, line: int, points: list[Point]) -> None:
    """Refuse a polygon whose sides cross or that has no area (pymunk could not hold it)."""
    n = len(points)
    if abs(signed_area(points)) < 1e-12:
        raise reader.fail(line, "'points' enclose no area")
    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):
                continue  # neighbours share a corner
            if _crossing(points[i], points[(i + 1) % n], points[j], points[(j + 1) % n]):
                raise reader.fail(
                    line, f"the polygon's sides {i + 1} and {j + 1} cross; list its corners "
                    "in order around it",
                )  # fmt: skip


def _crossing(a: Point, b: Point, c: Point, d: Point) -> bool:
    """Whether the segments a-b and c-d touch or cross."""

    def side(p: Point, q: Point, r: Point) -> float:
        return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])

    d1, d2, d3, d4 = side(c, d, a), side(c, d, b), side(a, b, c), side(a, b, d)
    if ((d1 > 0) != (d2 > 0)) and ((d3 > 0) != (d4 > 0)) and 0 not in (d1, d2, d3, d4):
        return True

    def on(p: Point, q: Point, r: Point) -> bool:
        return min(p[0], q[0]) <= r[0] <= max(p[0], q[0]) and min(p[1], q[1]) <= r[1] <= max(
            p[1], q[1]
        )

    return (
        (d1 == 0 and on(c, d, a))
        or (d2 == 0 and on(c, d, b))
        or (d3 == 0 and on(a, b, c))
        or (d4 == 0 and on(a, b, d))
    )


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


_DRIVE_KEYS = {
    "wheel_separation",
    "wheel_radius",
    "max_linear",
    "max_angular",
    "max_linear_accel",
    "cmd_vel",
    "odom",
    "joint_states",
}
_LIDAR_KEYS = {
    "type",
    "frame_id",
    "topic",
    "rate",
    "samples",
    "angle_min",
    "angle_max",
    "range_min",
    "range_max",
}


def load_robot(path: Path) -> RobotModel:
    """Read a robot model file.

    Raises:
        WorldFileError: with file:line and what is expected.
    """
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
    drive = reader.mapping(data, "drive", "the wheels, limits and topics")
    reader.keys(drive, _DRIVE_KEYS, {"wheel_separation", "wheel_radius"}, "drive")
    odom = reader.mapping(drive, "odom", "topic, frame_id, child_frame_id, rate")
    reader.keys(odom, {"topic", "frame_id", "child_frame_id", "rate"}, set(), "odom")
    joints = reader.mapping(drive, "joint_states", "topic, rate, joints")
    reader.keys(joints, {"topic", "rate", "joints"}, set(), "joint_states")
    has_joints = "joint_states" in drive
    frames = _frames(reader, data)
    return RobotModel(
        name=reader.text(data, "name", path.stem),
        footprint=_footprint(reader, data),
        mass=reader.number(data, "mass", default=1.0, positive=True),
        wheel_separation=reader.number(drive, "wheel_separation", positive=True),
        wheel_radius=reader.number(drive, "wheel_radius", positive=True),
        max_linear=reader.number(drive, "max_linear", default=1.0, positive=True),
        max_angular=reader.number(drive, "max_angular", default=2.0, positive=True),
        max_linear_accel=reader.number(drive, "max_linear_accel", default=1.0, positive=True),
        cmd_vel=reader.text(drive, "cmd_vel", "cmd_vel"),
        odom_topic=reader.text(odom, "topic", "odom"),
        odom_frame=reader.text(odom, "frame_id", "odom"),
        base_frame=reader.text(odom, "child_frame_id", "base_footprint"),
        odom_rate=reader.number(odom, "rate", default=30.0, positive=True),
        joint_states_topic=reader.text(joints, "topic", "joint_states") if has_joints else None,
        joint_states_rate=reader.number(joints, "rate", default=30.0, positive=True)
        if has_joints
        else 0.0,
        joints=reader.texts(joints, "joints"),
        frames=frames,
        lidars=tuple(_lidar(reader, line, item, frames) for line, item in reader.sequence(
            data, "sensors", "sensors")),
        path=path,
    )  # fmt: skip


def _footprint(reader: _Reader, data: dict[str, Any]) -> Circle | Polygon:
    foot = reader.mapping(data, "footprint", "type: circle or box")
    if foot.get("type") == "circle":
        reader.keys(foot, {"type", "radius"}, {"radius"}, "a circle footprint")
        return Circle("footprint", (0.0, 0.0), reader.number(foot, "radius", positive=True))
    if foot.get("type") == "box":
        reader.keys(foot, {"type", "size", "offset"}, {"size"}, "a box footprint")
        size = reader.point(foot, "size")
        if min(size) <= 0:
            raise reader.fail(
                reader.line_of(foot, "size"), f"'size' must be positive, not {list(size)}"
            )
        offset = reader.point(foot, "offset") if "offset" in foot else (0.0, 0.0)
        return Polygon("footprint", tuple(_box(offset, size, 0.0)))
    raise reader.fail(foot[_LINE], "footprint type must be 'circle' or 'box'")


def _frames(reader: _Reader, data: dict[str, Any]) -> tuple[Frame, ...]:
    frames = []
    entries = reader.mapping(data, "frames", "frame name: {parent, xyz, rpy}")
    for name in entries:
        if name in (_LINE, _LINES):
            continue
        frame = reader.mapping(entries, name, "parent, xyz, rpy, joint")
        reader.keys(frame, {"parent", "xyz", "rpy", "joint"}, {"parent", "xyz"}, f"frame '{name}'")
        frames.append(
            Frame(
                str(name),
                reader.text(frame, "parent"),
                reader.point(frame, "xyz", 3),
                reader.point(frame, "rpy", 3) if "rpy" in frame else (0.0, 0.0, 0.0),
                reader.text(frame, "joint") if "joint" in frame else None,
            )
        )
    return tuple(frames)


def _lidar(reader: _Reader, line: int, item: Any, frames: tuple[Frame, ...]) -> Lidar:
    sensor = reader.item(line, item, "a sensor with 'type: lidar2d'")
    reader.keys(sensor, _LIDAR_KEYS | {"name", "noise_stddev", "xy"}, _LIDAR_KEYS, "a sensor")
    if sensor["type"] != "lidar2d":
        raise reader.fail(reader.line_of(sensor, "type"), "sensor type must be 'lidar2d'")
    frame_id = reader.text(sensor, "frame_id")
    xy = reader.point(sensor, "xy") if "xy" in sensor else _frame_xy(list(frames), frame_id)
    samples = reader.integer(sensor, "samples", minimum=1)
    angle_min = reader.number(sensor, "angle_min")
    angle_max = reader.number(sensor, "angle_max")
    if angle_max < angle_min or (samples > 1 and angle_max == angle_min):
        raise reader.fail(
            reader.line_of(sensor, "angle_max"),
            f"'angle_max' ({angle_max}) must be greater than 'angle_min' ({angle_min})",
        )
    range_min = reader.number(sensor, "range_min", minimum=0.0)
    range_max = reader.number(sensor, "range_max", positive=True)
    if range_min >= range_max:
        raise reader.fail(
            reader.line_of(sensor, "range_min"),
            f"'range_min' ({range_min}) must be less than 'range_max' ({range_max})",
        )
    return Lidar(
        reader.text(sensor, "name", "lidar"),
        frame_id,
        reader.text(sensor, "topic"),
        reader.number(sensor, "rate", positive=True),
        samples,
        angle_min,
        angle_max,
        range_min,
        range_max,
        reader.number(sensor, "noise_stddev", default=0.0, minimum=0.0),
        xy,
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
    physics = reader.mapping(data, "physics", "step and iterations")
    reader.keys(physics, {"step", "iterations"}, set(), "physics")
    step = reader.number(physics, "step", default=0.01, positive=True)
    seed = reader.integer(data, "seed", default=0)
    statics: list[Shape] = []
    for line, entry in reader.sequence(data, "static", "shapes"):
        statics += _shapes(reader, entry, line)
    dynamics = []
    for line, entry in reader.sequence(data, "dynamic", "shapes with a mass"):
        for shape in _shapes(reader, entry, line, _DYNAMIC_KEYS):
            dynamics.append(
                DynamicBody(
                    shape,
                    reader.number(entry, "mass", default=1.0, positive=True),
                    reader.flag(entry, "kinematic"),
                )
            )
    robots = []
    entries = []
    for line, item in reader.sequence(data, "robots", "robots"):
        entry = reader.item(line, item, "a robot with 'model:' and 'pose:'")
        reader.keys(entry, {"name", "model", "pose", "namespace"}, {"model", "pose"}, "a robot")
        model = _robot_model(
            reader.text(entry, "model"), path, reader.line_of(entry, "model"), str(path)
        )
        pose = reader.point(entry, "pose", 3)
        namespace = reader.text(entry, "namespace", "").strip("/")
        name = reader.text(entry, "name", model.name)
        robots.append(RobotSpec(name, model, pose, namespace))
        entries.append(entry)
    world = World(
        str(data.get("name", path.stem)),
        path,
        round(step * 1e9),
        reader.integer(physics, "iterations", default=10, minimum=1),
        seed,
        tuple(statics),
        tuple(dynamics),
        tuple(robots),
    )
    _check_spawns(reader, entries, world)
    return world


def _check_spawns(reader: _Reader, entries: list[dict[str, Any]], world: World) -> None:
    from rosl.sim.world import footprint_overlaps

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
