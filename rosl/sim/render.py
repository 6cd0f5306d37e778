"""Pictures instead of RViz: the world, footprints, paths, scan points and frames as SVG/PNG.

SVG is written by hand (a few element types; no library needed). PNG is drawn with Pillow at
three times the size and scaled down, which smooths the lines. A :class:`Scene` is plain data
in one fixed frame (metres); the simulator and ``rosl viz`` (live or from a bag) both fill one.
Frame labels are placed by :func:`place_labels`, so frames at one spot stay readable.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING
from xml.sax.saxutils import escape

if TYPE_CHECKING:
    from pathlib import Path

    from rosl.sim.simulation import Simulation

Point = tuple[float, float]
Box = tuple[float, float, float, float]  # left, top, right, bottom, in pixels (y down)
PATH_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e")
LABEL_OFFSET = 4.0  # pixels between a frame's origin and its label
LABEL_GAP = 2.0  # pixels kept free between two labels


@dataclass(slots=True)
class Scene:
    """Everything to draw, in one frame."""

    title: str = ""
    frame: str = "odom"
    polygons: list[list[Point]] = field(default_factory=list)
    segments: list[tuple[Point, Point]] = field(default_factory=list)
    circles: list[tuple[Point, float]] = field(default_factory=list)
    paths: list[tuple[str, list[Point]]] = field(default_factory=list)
    footprints: list[list[Point]] = field(default_factory=list)
    scan: list[Point] = field(default_factory=list)
    frames: list[tuple[str, Point, float]] = field(default_factory=list)  # name, origin, yaw

    def bounds(self) -> tuple[float, float, float, float]:
        """(min x, min y, max x, max y) of everything, with a margin."""
        xs: list[float] = []
        ys: list[float] = []
        for polygon in [*self.polygons, *self.footprints]:
            xs += [p[0] for p in polygon]
            ys += [p[1] for p in polygon]
        for a, b in self.segments:
            xs += [a[0], b[0]]
            ys += [a[1], b[1]]
        for (x, y), r in self.circles:
            xs += [x - r, x + r]
            ys += [y - r, y + r]
        for _, path in self.paths:
            xs += [p[0] for p in path]
            ys += [p[1] for p in path]
        xs += [p[0] for p in self.scan]
        ys += [p[1] for p in self.scan]
        xs += [f[1][0] for f in self.frames]
        ys += [f[1][1] for f in self.frames]
        if not xs:
            return (-1.0, -1.0, 1.0, 1.0)
        margin = 0.05 * max(max(xs) - min(xs), max(ys) - min(ys), 1.0)
        return (min(xs) - margin, min(ys) - margin, max(xs) + margin, max(ys) + margin)


def write(scene: Scene, path: Path, width: int = 900) -> Path:
    """Write ``scene`` to ``path`` (.svg or .png); return the path."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() == ".png":
        _png(scene, path, width)
    else:
        path.write_text(svg(scene, width), encoding="utf-8")
    return path


class _View:
    """Metres to pixels: x right, y up."""

    def __init__(self, scene: Scene, width: int) -> None:
        x0, y0, x1, y1 = scene.bounds()
        self.scale = width / (x1 - x0)
        self.x0, self.y1 = x0, y1
        self.width = width
        self.height = max(1, round((y1 - y0) * self.scale))
        self.top = 28  # room for the title

    def __call__(self, point: Point) -> Point:
        return (
            (point[0] - self.x0) * self.scale,
            self.top + (self.y1 - point[1]) * self.scale,
        )


def _overlaps(a: Box, b: Box, gap: float) -> bool:
    return a[0] < b[2] + gap and b[0] < a[2] + gap and a[1] < b[3] + gap and b[1] < a[3] + gap


def place_labels(
    anchors: list[Point],
    sizes: list[tuple[float, float]],
    offset: float = LABEL_OFFSET,
    gap: float = LABEL_GAP,
) -> list[Box]:
    """Boxes for labels beside their anchors (pixels, y down), no two of them overlapping.

    Each label, in order, takes the first free place of: below-right, above-right, below-left,
    above-left of its anchor. When all four touch a label placed before, it goes below-right,
    moved down under each label it would touch until it touches none.

    Args:
        anchors: the points the labels belong to.
        sizes: each label's (width, height).
        offset: the distance from the anchor to a label, on both axes.
        gap: the space kept free between two labels.

    Returns:
        One (left, top, right, bottom) box per label, in the order given.
    """
    placed: list[Box] = []
    for (x, y), (width, height) in zip(anchors, sizes, strict=True):
        corners = [
            (x + offset, y + offset),
            (x + offset, y - offset - height),
            (x - offset - width, y + offset),
            (x - offset - width, y - offset - height),
        ]
        boxes = [(left, top, left + width, top + height) for left, top in corners]
        box = next((b for b in boxes if not any(_overlaps(b, p, gap) for p in placed)), None)
        if box is None:
            box = boxes[0]
            while (hit := next((p for p in placed if _overlaps(box, p, gap)), None)) is not None:
                top = hit[3] + gap + 1e-6  # strictly below the label it touched
                box = (box[0], top, box[2], top + height)
        placed.append(box)
    return placed


def _axes(origin: Point, yaw: float, length: float) -> tuple[Point, Point]:
    x, y = origin
    return (
        (x + length * math.cos(yaw), y + length * math.sin(yaw)),
        (x - length * math.sin(yaw), y + length * math.cos(yaw)),
    )


def svg(scene: Scene, width: int = 900) -> str:
    """The scene as an SVG document."""
    view = _View(scene, width)
    height = view.height + view.top + 10
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'viewBox="0 0 {width} {height}">',
        f'<rect width="{width}" height="{height}" fill="white"/>',
        f'<text x="8" y="19" font-family="sans-serif" font-size="14">'
        f"{escape(scene.title)} (fixed frame: {escape(scene.frame)})</text>",
    ]

    def pts(points: list[Point]) -> str:
        return " ".join(f"{x:.1f},{y:.1f}" for x, y in map(view, points))

    for polygon in scene.polygons:
        parts.append(f'<polygon points="{pts(polygon)}" fill="#bbbbbb" stroke="#555555"/>')
    for a, b in scene.segments:
        (ax, ay), (bx, by) = view(a), view(b)
        parts.append(
            f'<line x1="{ax:.1f}" y1="{ay:.1f}" x2="{bx:.1f}" y2="{by:.1f}" '
            'stroke="#555555" stroke-width="3"/>'
        )
    for center, radius in scene.circles:
        cx, cy = view(center)
        parts.append(
            f'<circle cx="{cx:.1f}" cy="{cy:.1f}" r="{radius * view.scale:.1f}" '
            'fill="#bbbbbb" stroke="#555555"/>'
        )
    for x, y in map(view, scene.scan):
        parts.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="2" fill="#00bcd4"/>')
    for number, (_, path) in enumerate(scene.paths):
        if len(path) > 1:
            colour = PATH_COLOURS[number % len(PATH_COLOURS)]
            parts.append(
                f'<polyline points="{pts(path)}" fill="none" stroke="{colour}" stroke-width="2"/>'
            )
    for footprint in scene.footprints:
        parts.append(
            f'<polygon points="{pts(footprint)}" fill="#ffd54f" fill-opacity="0.8" '
            'stroke="#333333"/>'
        )
    length = 30 / view.scale
    origins = [view(origin) for _, origin, _ in scene.frames]
    # sans-serif at 11 px: about 0.62 em per character, 13 px from top to bottom
    sizes = [(0.62 * 11 * len(name), 13.0) for name, _, _ in scene.frames]
    labels = place_labels(origins, sizes)
    for (name, origin, yaw), (ox, oy), box in zip(scene.frames, origins, labels, strict=True):
        tip_x, tip_y = (view(p) for p in _axes(origin, yaw, length))
        parts.append(
            f'<line x1="{ox:.1f}" y1="{oy:.1f}" x2="{tip_x[0]:.1f}" y2="{tip_x[1]:.1f}" '
            'stroke="red" stroke-width="2"/>'
        )
        parts.append(
            f'<line x1="{ox:.1f}" y1="{oy:.1f}" x2="{tip_y[0]:.1f}" y2="{tip_y[1]:.1f}" '
            'stroke="green" stroke-width="2"/>'
        )
        if _moved(box, (ox, oy), 13.0):
            near = _nearest_corner(box, (ox, oy))
            parts.append(
                f'<line x1="{ox:.1f}" y1="{oy:.1f}" x2="{near[0]:.1f}" y2="{near[1]:.1f}" '
                'stroke="#999999" stroke-width="1"/>'
            )
        parts.append(
            f'<text x="{box[0]:.1f}" y="{box[3] - 2:.1f}" font-family="sans-serif" '
            f'font-size="11">{escape(name)}</text>'
        )
    parts.append("</svg>")
    return "\n".join(parts) + "\n"


def _png(scene: Scene, path: Path, width: int) -> None:
    from PIL import Image, ImageDraw

    factor = 3
    view = _View(scene, width * factor)
    view.top *= factor
    height = view.height + view.top + 10 * factor
    image = Image.new("RGB", (width * factor, height), "white")
    draw = ImageDraw.Draw(image)
    for polygon in scene.polygons:
        draw.polygon([view(p) for p in polygon], fill="#bbbbbb", outline="#555555")
    for a, b in scene.segments:
        draw.line([view(a), view(b)], fill="#555555", width=3 * factor)
    for center, radius in scene.circles:
        cx, cy = view(center)
        r = radius * view.scale
        draw.ellipse([cx - r, cy - r, cx + r, cy + r], fill="#bbbbbb", outline="#555555")
    dot = 2 * factor
    for x, y in map(view, scene.scan):
        draw.ellipse([x - dot, y - dot, x + dot, y + dot], fill="#00bcd4")
    for number, (_, points) in enumerate(scene.paths):
        if len(points) > 1:
            colour = PATH_COLOURS[number % len(PATH_COLOURS)]
            draw.line([view(p) for p in points], fill=colour, width=2 * factor, joint="curve")
    for footprint in scene.footprints:
        draw.polygon([view(p) for p in footprint], fill="#ffd54f", outline="#333333")
    length = 30 * factor / view.scale
    origins = [view(origin) for _, origin, _ in scene.frames]
    sizes = []
    for name, _, _ in scene.frames:
        left, top, right, bottom = draw.textbbox((0, 0), name, font_size=11 * factor)
        sizes.append((right - left, bottom - top))
    labels = place_labels(origins, sizes, LABEL_OFFSET * factor, LABEL_GAP * factor)
    for (name, origin, yaw), o, box, size in zip(scene.frames, origins, labels, sizes, strict=True):
        tip_x, tip_y = (view(p) for p in _axes(origin, yaw, length))
        draw.line([o, tip_x], fill="red", width=2 * factor)
        draw.line([o, tip_y], fill="green", width=2 * factor)
        if _moved(box, o, size[1] + LABEL_OFFSET * factor):
            draw.line([o, _nearest_corner(box, o)], fill="#999999", width=factor)
        left, top, _, _ = draw.textbbox((0, 0), name, font_size=11 * factor)
        draw.text((box[0] - left, box[1] - top), name, fill="black", font_size=11 * factor)
    draw.text(
        (8 * factor, 6 * factor),
        f"{scene.title} (fixed frame: {scene.frame})",
        fill="black",
        font_size=14 * factor,
    )
    image = image.resize((width, height // factor), Image.Resampling.LANCZOS)
    image.save(path)


def _moved(box: Box, anchor: Point, reach: float) -> bool:
    """Whether a label was pushed away from its anchor (then a thin line joins them)."""
    dx = max(box[0] - anchor[0], anchor[0] - box[2], 0.0)
    dy = max(box[1] - anchor[1], anchor[1] - box[3], 0.0)
    return dx > reach or dy > reach


def _nearest_corner(box: Box, anchor: Point) -> Point:
    corners = [(box[0], box[1]), (box[2], box[1]), (box[0], box[3]), (box[2], box[3])]
    return min(corners, key=lambda c: (c[0] - anchor[0]) ** 2 + (c[1] - anchor[1]) ** 2)


def footprint_points(
    footprint: object, pose: tuple[float, float, float], segments: int = 24
) -> list[Point]:
    """A robot footprint (circle or polygon, robot frame) placed at ``pose``."""
    from rosl.sim.worldfile import Circle, Polygon

    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    if isinstance(footprint, Circle):
        r = footprint.radius
        ring = [
            (r * math.cos(2 * math.pi * k / segments), r * math.sin(2 * math.pi * k / segments))
            for k in range(segments)
        ]
        ring.append((r, 0.0))  # a spoke shows the heading
        ring.append((0.0, 0.0))
        ring.append((r, 0.0))
    else:
        assert isinstance(footprint, Polygon)
        ring = list(footprint.points)
    return [(x + c * px - s * py, y + s * px + c * py) for px, py in ring]


def render_simulation(sim: Simulation, path: Path, frame: str = "odom") -> Path:
    """Draw a simulation's world and robots in the first robot's odom frame (or the world)."""
    from rosl.sim import lidar as lidar_cast
    from rosl.sim.worldfile import Circle, Polygon, Segment

    origin = sim.world.robots[0].pose if (frame == "odom" and sim.world.robots) else (0, 0, 0)
    ox, oy, oyaw = origin
    c, s = math.cos(-oyaw), math.sin(-oyaw)

    def local(point: Point) -> Point:
        dx, dy = point[0] - ox, point[1] - oy
        return (c * dx - s * dy, s * dx + c * dy)

    scene = Scene(title=f"{sim.world.name}, t = {sim.now_ns / 1e9:.1f} s", frame=frame)
    for shape in [*sim.world.statics, *(b.shape for b in sim.world.dynamics)]:
        if isinstance(shape, Circle):
            scene.circles.append((local(shape.center), shape.radius))
        elif isinstance(shape, Polygon):
            scene.polygons.append([local(p) for p in shape.points])
        elif isinstance(shape, Segment):
            scene.segments.append((local(shape.a), local(shape.b)))
    for sim_robot in sim.robots:
        scene.paths.append((sim_robot.name, [local((x, y)) for _, x, y, _ in sim_robot.path]))
        x, y, yaw = sim_robot.robot.pose
        (lx, ly), lyaw = local((x, y)), yaw - oyaw
        model = sim_robot.robot.spec.model
        scene.footprints.append(footprint_points(model.footprint, (lx, ly, lyaw)))
        scene.frames.append((model.base_frame, (lx, ly), lyaw))
        if sim_robot.last_scan is not None and model.lidars:
            lidar = model.lidars[0]
            _, ranges = sim_robot.last_scan
            angles = lidar_cast.angles(lidar)
            mx = lx + math.cos(lyaw) * lidar.xy[0] - math.sin(lyaw) * lidar.xy[1]
            my = ly + math.sin(lyaw) * lidar.xy[0] + math.cos(lyaw) * lidar.xy[1]
            for angle, distance in zip(angles, ranges, strict=True):
                if math.isfinite(distance) and distance > 0:
                    scene.scan.append(
                        (
                            mx + distance * math.cos(lyaw + angle),
                            my + distance * math.sin(lyaw + angle),
                        )
                    )
    if sim.world.robots:
        scene.frames.append(
            (sim.world.robots[0].model.odom_frame if frame == "odom" else "world", (0.0, 0.0), 0.0)
        )
    return write(scene, path)
