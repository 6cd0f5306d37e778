"""A differential-drive robot: commanded through a one-step force, never tunnelling.

The command is clamped to the model's limits and ramped at its acceleration limit; before
each physics step the body gets the force that brings its velocity to the ramped one in that
step, so pymunk's contact solver, which runs after, still stops the robot at walls (writing
velocities before ``step()`` would tunnel, and a ``velocity_func`` costs a Python callback
from inside every step). A groove joint along the heading, moved before every step while
the robot touches something, is the wheels' grip: the solver cannot slide the robot
sideways, so pushing on against an obstacle stalls it where it hit, as on Gazebo or a real
floor (driving free, the force alone keeps it on its heading, and the joint costs nothing).
Odometry is the body's motion relative to its spawn pose, in the ``odom`` frame.

The per-step reads and writes of the body go straight to chipmunk's C functions (pymunk's
``lib``, the same calls its properties make): the properties' Python layers cost more than
the physics step itself. The body is read once after each step and kept (pose, velocities).
"""

from __future__ import annotations

import importlib
import math
from typing import TYPE_CHECKING, Any

import pymunk

from rosl.sim.world import _pymunk_shape
from rosl.sim.worldfile import Circle, Polygon

if TYPE_CHECKING:
    from rosl.sim.worldfile import RobotSpec

ABSURD = 1e3  # m/s or rad/s: a command beyond this is a bug upstream, not a wish
GROOVE = 1e3  # metres: half the length of the line the robot may move along in one step
_CHIPMUNK: Any = importlib.import_module("pymunk._chipmunk")
_LIB: Any = _CHIPMUNK.lib  # what pymunk.Body's properties call
_FFI: Any = _CHIPMUNK.ffi


class DiffDriveRobot:
    """One robot in a pymunk space."""

    def __init__(self, spec: RobotSpec, space: pymunk.Space) -> None:
        self.spec = spec
        model = spec.model
        foot = model.footprint
        if isinstance(foot, Circle):
            moment = pymunk.moment_for_circle(model.mass, 0, foot.radius)
        else:
            assert isinstance(foot, Polygon)
            moment = pymunk.moment_for_poly(model.mass, list(foot.points))
        self.body = pymunk.Body(model.mass, moment)
        self.body.position = spec.pose[:2]
        self.body.angle = spec.pose[2]
        self.shape = _pymunk_shape(self.body, foot, local=True)
        self.shape.friction = 0.0
        space.add(self.body, self.shape)
        self.grip = pymunk.GrooveJoint(space.static_body, self.body, (0, 0), (1, 0), (0, 0))
        self._space = space
        self.contacts = 0  # obstacles touching the robot now (the simulation counts them)
        self._gripping = False
        self.target = (0.0, 0.0)
        self.v = 0.0
        self.w = 0.0
        self.wheels = [0.0, 0.0]  # left, right joint angles (rad)
        self.wheel_rates = [0.0, 0.0]  # left, right joint speeds (rad/s)
        self.collisions = 0
        self._alpha = 2.0 * model.max_linear_accel / model.wheel_separation
        self._accel = model.max_linear_accel
        self._half = model.wheel_separation / 2
        self._radius = model.wheel_radius
        self._c_body = self.body._body  # chipmunk's cpBody*
        # the body as the last step left it (nothing else moves it between steps)
        self._x, self._y = self.body.position
        self._angle = self.body.angle
        self._velocity = (0.0, 0.0)
        self._turn = 0.0
        self._dt = 0.0
        self._dv = self._dw = self._push = self._twist = 0.0
        x0, y0, yaw0 = spec.pose  # the odom frame: the spawn pose, and the turn back from it
        self._origin = (x0, y0, yaw0, math.cos(-yaw0), math.sin(-yaw0))

    def command(self, linear: float, angular: float) -> str | None:
        """Set the velocity command; return a warning text when it had to be clamped or dropped."""
        model = self.spec.model
        if not (math.isfinite(linear) and math.isfinite(angular)):
            return (
                f"ignored a cmd_vel with non-finite values (linear.x={linear}, angular.z={angular})"
            )
        if abs(linear) > ABSURD or abs(angular) > ABSURD:
            return f"ignored an absurd cmd_vel (linear.x={linear}, angular.z={angular})"
        clamped = (
            max(-model.max_linear, min(model.max_linear, linear)),
            max(-model.max_angular, min(model.max_angular, angular)),
        )
        self.target = clamped
        if clamped != (linear, angular):
            return (
                f"clamped cmd_vel ({linear:g}, {angular:g}) to the {model.name}'s limits "
                f"({clamped[0]:g}, {clamped[1]:g})"
            )
        return None

    def before_step(self, dt: float) -> None:
        """Ramp the velocity towards the command and have this step's physics reach it.

        The velocity is set as a force for the one step (pymunk clears forces after each):
        the solver still acts on it afterwards, so contacts stop the robot, and no Python
        velocity callback runs inside the step. Pymunk turns the body first (by its current
        angular velocity) and integrates velocities after, so the linear velocity is aimed
        along the heading the body will have then.
        """
        if dt != self._dt:
            self._prepare(dt)
        dv, dw = self._dv, self._dw
        target_v, target_w = self.target
        v = self.v + max(-dv, min(dv, target_v - self.v))
        w = self.w + max(-dw, min(dw, target_w - self.w))
        self.v, self.w = v, w
        turn = self._turn
        heading = self._angle + turn * dt
        push, twist = self._push, self._twist
        vx, vy = self._velocity
        _LIB.cpBodySetForce(
            self._c_body, ((v * math.cos(heading) - vx) * push, (v * math.sin(heading) - vy) * push)
        )
        _LIB.cpBodySetTorque(self._c_body, (w - turn) * twist)
        if self.contacts or self._gripping:
            self._grip(heading, dt)

    def _prepare(self, dt: float) -> None:
        """What a step of ``dt`` takes that does not change from step to step."""
        body = self.body
        self._dt = dt
        self._dv = self._accel * dt
        self._dw = self._alpha * dt
        self._push = body.mass / dt  # force that changes the velocity by 1 m/s in one step
        self._twist = body.moment / dt

    def _grip(self, heading: float, dt: float) -> None:
        """Put the wheels' grip along the heading, through where the robot is about to be.

        pymunk moves the body first and solves the constraints after, so the groove goes
        where this step's motion takes the body, along the heading it will have there.
        """
        if not self.contacts:  # driving free again
            self._space.remove(self.grip)
            self._gripping = False
            return
        vx, vy = self._velocity
        x = self._x + vx * dt
        y = self._y + vy * dt
        dx, dy = GROOVE * math.cos(heading), GROOVE * math.sin(heading)
        self.grip.groove_a = (x - dx, y - dy)
        self.grip.groove_b = (x + dx, y + dy)
        if not self._gripping:
            self._space.add(self.grip)
            self._gripping = True

    def after_step(self, dt: float) -> float:
        """Read the body back, advance the wheel joints; return the distance it moved."""
        c_body = self._c_body
        position = _LIB.cpBodyGetPosition(c_body)
        velocity = _LIB.cpBodyGetVelocity(c_body)
        angle = self._angle = _LIB.cpBodyGetAngle(c_body)
        w = self._turn = _LIB.cpBodyGetAngularVelocity(c_body)
        x, y, vx, vy = position.x, position.y, velocity.x, velocity.y
        moved = math.hypot(x - self._x, y - self._y)
        self._x, self._y, self._velocity = x, y, (vx, vy)
        forward = vx * math.cos(angle) + vy * math.sin(angle)
        half, radius = self._half, self._radius
        left = (forward - w * half) / radius
        right = (forward + w * half) / radius
        rates, wheels = self.wheel_rates, self.wheels
        rates[0], rates[1] = left, right
        wheels[0] += left * dt
        wheels[1] += right * dt
        return moved

    @property
    def pose(self) -> tuple[float, float, float]:
        """(x, y, yaw) in the world."""
        return (self._x, self._y, self._angle)

    def odometry(self) -> tuple[tuple[float, float, float], tuple[float, float]]:
        """((x, y, yaw) in the odom frame, (forward speed, yaw rate))."""
        x, y, yaw, forward, turn = self.odometry_values()
        return (x, y, yaw), (forward, turn)

    def odometry_values(self) -> tuple[float, float, float, float, float]:
        """:meth:`odometry` flat: x, y, yaw in the odom frame, forward speed, yaw rate."""
        x0, y0, yaw0, c, s = self._origin
        x, y, yaw = self._x, self._y, self._angle
        dx, dy = x - x0, y - y0
        vx, vy = self._velocity
        forward = vx * math.cos(yaw) + vy * math.sin(yaw)
        return c * dx - s * dy, s * dx + c * dy, yaw - yaw0, forward, self._turn
