"""A differential-drive robot: commanded through pymunk's velocity function, never tunnelling.

The command is clamped to the model's limits and ramped at its acceleration limit; each
physics step sets the body's velocity from inside ``velocity_func``, so pymunk's contact
solver still stops the robot at walls (writing velocities before ``step()`` would tunnel).
A groove joint along the heading, moved before every step while the robot touches something,
is the wheels' grip: the solver cannot slide the robot sideways, so pushing on against an
obstacle stalls it where it hit, as on Gazebo or a real floor (driving free, the velocity
function alone keeps it on its heading, and the joint costs nothing). Odometry is the body's
motion relative to its spawn pose, in the ``odom`` frame.

The per-step reads and writes of the body go straight to chipmunk's C functions (pymunk's
``lib``, the same calls its properties make): the properties' Python layers cost more than
the physics step itself.
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
_LIB: Any = importlib.import_module("pymunk._chipmunk").lib  # what pymunk.Body's properties call


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
        self.body.velocity_func = self._velocity
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

    def _velocity(
        self, body: pymunk.Body, gravity: tuple[float, float], damping: float, dt: float
    ) -> None:
        dv = self._accel * dt
        dw = self._alpha * dt
        target_v, target_w = self.target
        v = self.v + max(-dv, min(dv, target_v - self.v))
        w = self.w + max(-dw, min(dw, target_w - self.w))
        self.v, self.w = v, w
        c_body = self._c_body
        angle = _LIB.cpBodyGetAngle(c_body)
        _LIB.cpBodySetVelocity(c_body, (v * math.cos(angle), v * math.sin(angle)))
        _LIB.cpBodySetAngularVelocity(c_body, w)

    def before_step(self, dt: float) -> None:
        """Put the wheels' grip along the heading, through where the robot is about to be.

        pymunk moves the body first and solves the constraints after, so the groove goes
        where this step's motion takes the body, along the heading it will have there.
        """
        if not self.contacts:  # driving free: nothing to do (the common case)
            if self._gripping:
                self._space.remove(self.grip)
                self._gripping = False
            return
        body = self.body
        x = body.position.x + body.velocity.x * dt
        y = body.position.y + body.velocity.y * dt
        angle = body.angle + body.angular_velocity * dt
        dx, dy = GROOVE * math.cos(angle), GROOVE * math.sin(angle)
        self.grip.groove_a = (x - dx, y - dy)
        self.grip.groove_b = (x + dx, y + dy)
        if not self._gripping:
            self._space.add(self.grip)
            self._gripping = True

    def after_step(self, dt: float) -> None:
        """Advance the wheel joints with the motion the solver allowed."""
        c_body = self._c_body
        angle = _LIB.cpBodyGetAngle(c_body)
        velocity = _LIB.cpBodyGetVelocity(c_body)
        forward = velocity.x * math.cos(angle) + velocity.y * math.sin(angle)
        w = _LIB.cpBodyGetAngularVelocity(c_body)
        half, radius = self._half, self._radius
        left = (forward - w * half) / radius
        right = (forward + w * half) / radius
        rates, wheels = self.wheel_rates, self.wheels
        rates[0], rates[1] = left, right
        wheels[0] += left * dt
        wheels[1] += right * dt

    @property
    def pose(self) -> tuple[float, float, float]:
        """(x, y, yaw) in the world."""
        c_body = self._c_body
        position = _LIB.cpBodyGetPosition(c_body)
        return (position.x, position.y, _LIB.cpBodyGetAngle(c_body))

    def odometry(self) -> tuple[tuple[float, float, float], tuple[float, float]]:
        """((x, y, yaw) in the odom frame, (forward speed, yaw rate))."""
        x0, y0, yaw0 = self.spec.pose
        x, y, yaw = self.pose
        c, s = math.cos(-yaw0), math.sin(-yaw0)
        dx, dy = x - x0, y - y0
        c_body = self._c_body
        velocity = _LIB.cpBodyGetVelocity(c_body)
        forward = velocity.x * math.cos(yaw) + velocity.y * math.sin(yaw)
        return (c * dx - s * dy, s * dx + c * dy, yaw - yaw0), (
            forward,
            _LIB.cpBodyGetAngularVelocity(c_body),
        )
