"""A world file as a pymunk space, plus the flat geometry that ray casting uses."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import pymunk

from rosl.sim.model import signed_area
from rosl.sim.worldfile import Circle, Polygon, RobotSpec, Segment, Shape

if TYPE_CHECKING:
    from rosl.sim.worldfile import World


def _pymunk_shape(body: pymunk.Body, shape: Shape, *, local: bool = False) -> pymunk.Shape:
    """A pymunk shape on ``body`` (world coordinates, or body-local when ``local``)."""
    if isinstance(shape, Circle):
        offset = (0.0, 0.0) if local else shape.center
        return pymunk.Circle(body, shape.radius, offset)
    if isinstance(shape, Polygon):
        return pymunk.Poly(body, list(shape.points))
    return pymunk.Segment(body, shape.a, shape.b, shape.radius)


def _pymunk_shapes(body: pymunk.Body, shape: Shape) -> list[pymunk.Shape]:
    """The pymunk shapes of an obstacle: a polygon that is not convex in convex pieces.

    ``pymunk.Poly`` takes the convex hull of its points, so an L-shaped wall would collide
    where the LiDAR sees free space; pymunk's own decomposition (exact at tolerance 0) keeps
    the two in agreement.
    """
    if isinstance(shape, Polygon) and not _convex(shape.points):
        from pymunk.autogeometry import convex_decomposition

        points = list(shape.points)
        if signed_area(points) < 0:
            points.reverse()
        hulls = convex_decomposition([*points, points[0]], 0.0)
        return [pymunk.Poly(body, [(p.x, p.y) for p in hull[:-1]]) for hull in hulls]
    return [_pymunk_shape(body, shape)]


def _convex(points: tuple[tuple[float, float], ...]) -> bool:
    n = len(points)
    turns = [
        (points[(k + 1) % n][0] - points[k][0]) * (points[(k + 2) % n][1] - points[k][1])
        - (points[(k + 1) % n][1] - points[k][1]) * (points[(k + 2) % n][0] - points[k][0])
        for k in range(n)
    ]
    return all(t >= 0 for t in turns) or all(t <= 0 for t in turns)


def footprint_overlaps(robot: RobotSpec, statics: tuple[Shape, ...]) -> str | None:
    """The name of a static shape the robot's spawn footprint overlaps, if any."""
    space = pymunk.Space()
    names: dict[pymunk.Shape, str] = {}
    for shape in statics:
        for made in _pymunk_shapes(space.static_body, shape):
            names[made] = shape.name
            space.add(made)
    body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
    body.position = robot.pose[:2]
    body.angle = robot.pose[2]
    probe = _pymunk_shape(body, robot.model.footprint, local=True)
    space.add(body, probe)
    hits = space.shape_query(probe)
    return names[hits[0].shape] if hits else None


class Geometry:
    """Obstacles as numpy arrays for ray casting: one-sided edges and circles (x, y, r).

    An edge is ``(ax, ay, bx, by, nx, ny, n.a)`` with ``n`` its unit normal on the side it is
    seen from: polygon edges run counter-clockwise and are seen from outside only; a free
    segment's side is two edges, one each way, so it is seen from both sides. All of it is
    computed once, so a scan only asks which edges face the sensor (``n.a - n.s < 0``).
    """

    def __init__(self, shapes: tuple[Shape, ...]) -> None:
        edges: list[tuple[float, float, float, float]] = []
        circles: list[tuple[float, float, float]] = []
        for shape in shapes:
            if isinstance(shape, Circle):
                circles.append((*shape.center, shape.radius))
            elif isinstance(shape, Polygon):
                points = list(shape.points)
                if signed_area(points) < 0:
                    points.reverse()
                for k, (x1, y1) in enumerate(points):
                    x2, y2 = points[(k + 1) % len(points)]
                    edges.append((x1, y1, x2, y2))
            elif isinstance(shape, Segment):  # pymunk's capsule: two sides and two round ends
                (ax, ay), (bx, by) = shape.a, shape.b
                length = math.hypot(bx - ax, by - ay) or 1.0
                nx, ny = -(by - ay) / length * shape.radius, (bx - ax) / length * shape.radius
                for dx, dy in ((nx, ny), (-nx, -ny)):
                    edges.append((ax + dx, ay + dy, bx + dx, by + dy))  # seen from both sides
                    edges.append((bx + dx, by + dy, ax + dx, ay + dy))
                circles += [(ax, ay, shape.radius), (bx, by, shape.radius)]
        ends = np.array(edges, dtype=np.float64).reshape(-1, 4)
        ex, ey = ends[:, 2] - ends[:, 0], ends[:, 3] - ends[:, 1]
        sizes = np.hypot(ex, ey)
        kept = sizes > 0
        ends, ex, ey, sizes = ends[kept], ex[kept], ey[kept], sizes[kept]
        normal_x, normal_y = ey / sizes, -ex / sizes  # outward for a counter-clockwise edge
        offset = normal_x * ends[:, 0] + normal_y * ends[:, 1]
        self.edges = np.column_stack((ends, normal_x, normal_y, offset))
        self.normal_angles = np.arctan2(normal_y, normal_x)
        self.circles = np.array(circles, dtype=np.float64).reshape(-1, 3)

    @classmethod
    def joined(cls, geometries: list[Geometry]) -> Geometry:
        """One geometry holding the edges and circles of several."""
        if len(geometries) == 1:
            return geometries[0]
        joined = cls(())
        joined.edges = np.concatenate([g.edges for g in geometries])
        joined.normal_angles = np.concatenate([g.normal_angles for g in geometries])
        joined.circles = np.concatenate([g.circles for g in geometries])
        return joined


class WorldSpace:
    """The pymunk space of a world: statics, dynamic bodies, and the ray-cast geometry."""

    def __init__(self, world: World) -> None:
        self.world = world
        self.space = pymunk.Space()
        self.space.gravity = (0.0, 0.0)
        self.space.iterations = world.iterations
        for shape in world.statics:
            for made in _pymunk_shapes(self.space.static_body, shape):
                made.friction = 0.0
                self.space.add(made)
        self.bodies: list[tuple[pymunk.Body, Shape]] = []
        for dynamic in world.dynamics:
            self._add_body(dynamic.shape, dynamic.mass, dynamic.kinematic)
        self.geometry = Geometry(world.statics)

    def _add_body(self, shape: Shape, mass: float, kinematic: bool) -> None:
        center = _centroid(shape)
        local = _translate(shape, -center[0], -center[1])
        if kinematic:
            body = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        else:
            if isinstance(local, Circle):
                moment = pymunk.moment_for_circle(mass, 0, local.radius, local.center)
            elif isinstance(local, Polygon):
                moment = pymunk.moment_for_poly(mass, list(local.points))
            else:
                moment = pymunk.moment_for_segment(mass, local.a, local.b, local.radius)
            body = pymunk.Body(mass, moment)
        body.position = center
        self.space.add(body)
        for made in _pymunk_shapes(body, local):
            made.friction = 0.5
            self.space.add(made)
        self.bodies.append((body, local))

    def dynamic_geometry(self) -> Geometry:
        """The dynamic bodies' shapes where they are now (for ray casting)."""
        placed: list[Shape] = []
        for body, local in self.bodies:
            c, s = math.cos(body.angle), math.sin(body.angle)
            px, py = body.position
            if isinstance(local, Circle):
                placed.append(
                    Circle(local.name, (px + local.center[0], py + local.center[1]), local.radius)
                )
            elif isinstance(local, Polygon):
                placed.append(
                    Polygon(
                        local.name,
                        tuple((px + c * x - s * y, py + s * x + c * y) for x, y in local.points),
                    )
                )
            else:
                (ax, ay), (bx, by) = local.a, local.b
                placed.append(
                    Segment(
                        local.name,
                        (px + c * ax - s * ay, py + s * ax + c * ay),
                        (px + c * bx - s * by, py + s * bx + c * by),
                        local.radius,
                    )
                )
        return Geometry(tuple(placed))


def _centroid(shape: Shape) -> tuple[float, float]:
    if isinstance(shape, Circle):
        return shape.center
    if isinstance(shape, Polygon):
        xs, ys = zip(*shape.points, strict=True)
        return (sum(xs) / len(xs), sum(ys) / len(ys))
    return ((shape.a[0] + shape.b[0]) / 2, (shape.a[1] + shape.b[1]) / 2)


def _translate(shape: Shape, dx: float, dy: float) -> Shape:
    if isinstance(shape, Circle):
        return Circle(shape.name, (shape.center[0] + dx, shape.center[1] + dy), shape.radius)
    if isinstance(shape, Polygon):
        return Polygon(shape.name, tuple((x + dx, y + dy) for x, y in shape.points))
    return Segment(
        shape.name,
        (shape.a[0] + dx, shape.a[1] + dy),
        (shape.b[0] + dx, shape.b[1] + dy),
        shape.radius,
    )
