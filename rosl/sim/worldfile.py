"""World and robot files (YAML, ``format: rosl-world/1`` / ``rosl-robot/1``), validated.

Every problem is one line naming the file, the line, and what is expected: unknown keys,
wrong types, negative sizes, unknown robot models, robots spawned inside walls or on top of
each other. Geometry is in metres and radians, poses are ``[x, y, yaw]``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

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
)
from rosl.sim.yaml_reader import LINE as _LINE
from rosl.sim.yaml_reader import LINES as _LINES
from rosl.sim.yaml_reader import YamlReader as _Reader

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
