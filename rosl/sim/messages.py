"""The simulator's messages: Clock, Odometry, TF, JointState, LaserScan, markers, URDF.

Plain builders from simulation state to ROS 2 messages (Gazebo's conventions: odometry
covariances of its diff-drive plugin, ``odom -> base_footprint`` on ``/tf``, fixed frames once on
``/tf_static``, scans with +inf for no return). The world's geometry goes out as a
``visualization_msgs/MarkerArray`` in the ``world`` frame, which ``/tf_static`` ties to each
robot's odometry frame at its spawn pose.
"""

from __future__ import annotations

import math
import struct
from typing import TYPE_CHECKING, Any
from xml.sax.saxutils import quoteattr

from rosl.idl.registry import get_message_class
from rosl.sim import encode
from rosl.sim import lidar as lidar_cast
from rosl.sim.worldfile import Circle, Polygon, Segment

if TYPE_CHECKING:
    import numpy as np

    from rosl.sim.simulation import SimRobot
    from rosl.sim.worldfile import Lidar, RobotModel, RobotSpec, World

NS = 1_000_000_000
WORLD_FRAME = "world"
# Gazebo's diff-drive plugin: small variance on x, y, yaw; "unknown" (1e12) on z, roll, pitch
POSE_COVARIANCE = (1e-5, 1e-5, 1e12, 1e12, 1e12, 1e-3)


def msg(type_name: str) -> Any:
    """A message class (the registry caches it)."""
    return get_message_class(type_name)


def stamp(now_ns: int) -> Any:
    """A builtin_interfaces/Time."""
    sec, nanosec = divmod(now_ns, NS)
    return msg("builtin_interfaces/msg/Time")(sec=sec, nanosec=nanosec)


def quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of roll-pitch-yaw angles."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def clock(now_ns: int) -> Any:
    """rosgraph_msgs/Clock."""
    return msg("rosgraph_msgs/msg/Clock")(clock=stamp(now_ns))


def odometry(sim_robot: SimRobot, now_ns: int) -> Any:
    """nav_msgs/Odometry of a robot, in its odom frame."""
    model = sim_robot.robot.spec.model
    (x, y, yaw), (forward, turn) = sim_robot.robot.odometry()
    message = msg("nav_msgs/msg/Odometry")()
    message.header.stamp = stamp(now_ns)
    message.header.frame_id = model.odom_frame
    message.child_frame_id = model.base_frame
    pose = message.pose.pose
    pose.position.x, pose.position.y = x, y
    pose.orientation.z, pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    message.twist.twist.linear.x = forward
    message.twist.twist.angular.z = turn
    covariance = [0.0] * 36
    for k, value in enumerate(POSE_COVARIANCE):
        covariance[k * 7] = value
    message.pose.covariance = covariance
    message.twist.covariance = covariance
    return message


def multiply(
    a: tuple[float, float, float, float], b: tuple[float, float, float, float]
) -> tuple[float, float, float, float]:
    """The quaternion product a * b (rotate by b, then by a)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def transform(
    parent: str,
    child: str,
    now_ns: int,
    xyz: tuple[float, float, float],
    rpy: tuple[float, float, float],
    spin: float = 0.0,
) -> Any:
    """A geometry_msgs/TransformStamped (``spin``: a joint angle about the child's z axis)."""
    message = msg("geometry_msgs/msg/TransformStamped")()
    message.header.stamp = stamp(now_ns)
    message.header.frame_id = parent
    message.child_frame_id = child
    t = message.transform.translation
    t.x, t.y, t.z = xyz
    r = message.transform.rotation
    rotation = quaternion(*rpy)
    if spin:
        rotation = multiply(rotation, (0.0, 0.0, math.sin(spin / 2), math.cos(spin / 2)))
    r.x, r.y, r.z, r.w = rotation
    return message


def odom_tf(sim_robot: SimRobot, now_ns: int) -> Any:
    """tf2_msgs/TFMessage with ``odom -> base_footprint``."""
    model = sim_robot.robot.spec.model
    (x, y, yaw), _ = sim_robot.robot.odometry()
    return msg("tf2_msgs/msg/TFMessage")(
        transforms=[
            transform(model.odom_frame, model.base_frame, now_ns, (x, y, 0.0), (0.0, 0.0, yaw))
        ]
    )


def static_tf(world: World, now_ns: int) -> Any:
    """tf2_msgs/TFMessage with every fixed frame: world -> odom (spawn pose), and the robots'."""
    transforms = []
    for spec in world.robots:
        model = spec.model
        x, y, yaw = spec.pose
        transforms.append(
            transform(WORLD_FRAME, model.odom_frame, now_ns, (x, y, 0.0), (0.0, 0.0, yaw))
        )
        transforms += [
            transform(frame.parent, frame.name, now_ns, frame.xyz, frame.rpy)
            for frame in model.frames
            if frame.joint is None
        ]
    return msg("tf2_msgs/msg/TFMessage")(transforms=transforms)


def wheel_tf(sim_robot: SimRobot, now_ns: int) -> Any | None:
    """tf2_msgs/TFMessage with the wheel links turned by their joints (robot_state_publisher)."""
    model = sim_robot.robot.spec.model
    moving = [f for f in model.frames if f.joint is not None]
    if not moving:
        return None
    angles = dict(zip(model.joints, sim_robot.robot.wheels, strict=False))
    return msg("tf2_msgs/msg/TFMessage")(
        transforms=[
            transform(
                frame.parent,
                frame.name,
                now_ns,
                frame.xyz,
                frame.rpy,
                angles.get(frame.joint or "", 0.0),
            )
            for frame in moving
        ]
    )


def joint_states(sim_robot: SimRobot, now_ns: int) -> Any:
    """sensor_msgs/JointState of the wheels (angle and speed)."""
    import numpy as np

    robot = sim_robot.robot
    model = robot.spec.model
    message = msg("sensor_msgs/msg/JointState")()
    message.header.stamp = stamp(now_ns)
    message.name = list(model.joints)
    message.position = np.array(robot.wheels[: len(model.joints)], dtype=np.float64)
    message.velocity = np.array(robot.wheel_rates[: len(model.joints)], dtype=np.float64)
    message.effort = np.zeros(0, dtype=np.float64)
    return message


def laser_scan(lidar: Lidar, ranges: np.ndarray, now_ns: int) -> Any:
    """sensor_msgs/LaserScan with Gazebo's conventions."""
    import numpy as np

    message = msg("sensor_msgs/msg/LaserScan")()
    message.header.stamp = stamp(now_ns)
    message.header.frame_id = lidar.frame_id
    message.angle_min = lidar.angle_min
    message.angle_max = lidar.angle_max
    message.angle_increment = lidar_cast.increment(lidar)
    message.time_increment = 0.0
    message.scan_time = 1.0 / lidar.rate
    message.range_min = lidar.range_min
    message.range_max = lidar.range_max
    message.ranges = ranges
    message.intensities = np.zeros(0, dtype=np.float32)
    return message


def world_markers(world: World, now_ns: int) -> Any:
    """visualization_msgs/MarkerArray of the static geometry (and where movable bodies start)."""
    marker_type = msg("visualization_msgs/msg/Marker")
    point = msg("geometry_msgs/msg/Point")
    markers = []
    lines = marker_type()
    lines.header.stamp = stamp(now_ns)
    lines.header.frame_id = WORLD_FRAME
    lines.ns, lines.id, lines.type, lines.action = "walls", 0, marker_type.LINE_LIST, 0
    lines.pose.orientation.w = 1.0
    lines.scale.x = 0.02
    lines.color.r = lines.color.g = lines.color.b = 0.3
    lines.color.a = 1.0
    shapes = list(world.statics) + [body.shape for body in world.dynamics]
    for shape in shapes:
        if isinstance(shape, Polygon):
            pts = list(shape.points)
            for a, b in zip(pts, pts[1:] + pts[:1], strict=True):
                lines.points += [point(x=a[0], y=a[1]), point(x=b[0], y=b[1])]
        elif isinstance(shape, Segment):
            lines.points += [point(x=shape.a[0], y=shape.a[1]), point(x=shape.b[0], y=shape.b[1])]
    markers.append(lines)
    for number, shape in enumerate((s for s in shapes if isinstance(s, Circle)), start=1):
        cylinder = marker_type()
        cylinder.header = lines.header
        cylinder.ns, cylinder.id, cylinder.type, cylinder.action = (
            "cylinders",
            number,
            marker_type.CYLINDER,
            0,
        )
        cylinder.pose.position.x, cylinder.pose.position.y = shape.center
        cylinder.pose.position.z = 0.25
        cylinder.pose.orientation.w = 1.0
        cylinder.scale.x = cylinder.scale.y = 2 * shape.radius
        cylinder.scale.z = 0.5
        cylinder.color.r = cylinder.color.g = cylinder.color.b = 0.45
        cylinder.color.a = 1.0
        cylinder.text = shape.name
        markers.append(cylinder)
    return msg("visualization_msgs/msg/MarkerArray")(markers=markers)


def robot_description(spec: RobotSpec) -> Any:
    """std_msgs/String with a URDF of the robot model (links, fixed and wheel joints)."""
    return msg("std_msgs/msg/String")(data=urdf(spec.model))


def urdf(model: RobotModel) -> str:
    """A URDF document of a robot model: its frames as links, with the footprint drawn."""
    foot = model.footprint
    if isinstance(foot, Circle):
        geometry = f'<cylinder radius="{foot.radius:g}" length="0.1"/>'
    else:
        xs = [p[0] for p in foot.points]
        ys = [p[1] for p in foot.points]
        geometry = f'<box size="{max(xs) - min(xs):g} {max(ys) - min(ys):g} 0.1"/>'
    links = [model.base_frame, *(f.name for f in model.frames)]
    lines = ['<?xml version="1.0"?>', f"<robot name={quoteattr(model.name)}>"]
    for link in dict.fromkeys(links):
        if link == model.base_frame:
            lines.append(
                f'  <link name={quoteattr(link)}><visual><origin xyz="0 0 0.05"/>'
                f"<geometry>{geometry}</geometry></visual></link>"
            )
        else:
            lines.append(f"  <link name={quoteattr(link)}/>")
    for frame in model.frames:
        kind = "continuous" if frame.joint else "fixed"
        name = frame.joint or f"{frame.name}_joint"
        axis = '<axis xyz="0 0 1"/>' if frame.joint else ""
        xyz = " ".join(f"{v:g}" for v in frame.xyz)
        rpy = " ".join(f"{v:g}" for v in frame.rpy)
        lines.append(
            f'  <joint name={quoteattr(name)} type="{kind}">'
            f"<parent link={quoteattr(frame.parent)}/><child link={quoteattr(frame.name)}/>"
            f'<origin xyz="{xyz}" rpy="{rpy}"/>{axis}</joint>'
        )
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


# --- the same messages as CDR bytes (the sim's hot path; see encode.py) ------------------------

_STAMP_INTO = struct.Struct("<iI").pack_into
_POSE_INTO = struct.Struct("<dd24xdd").pack_into  # x, y, (z, qx, qy: 0), qz, qw
_TWIST_INTO = struct.Struct("<d32xd").pack_into  # linear x, (4 zeros), angular z
_ODOM_TWIST = 7 * 8 + 36 * 8  # from the pose to the twist: the pose, its covariance
_ODOM_TAIL = _ODOM_TWIST + 6 * 8 + 36 * 8  # from the pose to the end
_COVARIANCE = tuple(POSE_COVARIANCE[k // 7] if k % 7 == 0 else 0.0 for k in range(36))


def clock_bytes(now_ns: int) -> bytes:
    """rosgraph_msgs/Clock as CDR."""
    return encode.clock(now_ns)


Transform = tuple[bytes, bytes, tuple[float, ...]]
NOT_DUE, TRANSFORM, MESSAGE = 0, 1, 2  # what RobotEncoder.tick_at makes of odometry, wheels


class RobotEncoder:
    """One robot's high-rate messages as CDR, with what is fixed about them prepared once.

    Frame names are encoded, the wheel links' fixed rotations and the scans' constant fields
    computed at construction; a message then costs its moving numbers and one ``pack``. The
    ``*_at`` methods serve the sim node's tick: they take the stamp split once for all of a
    tick's messages and add their transforms' values to the tick's one ``/tf`` message (for
    :func:`rosl.sim.encode.tf_struct` of the frames they add to the key).
    """

    def __init__(self, sim_robot: SimRobot) -> None:
        self.sim_robot = sim_robot
        model = sim_robot.robot.spec.model
        self.odom_frame = model.odom_frame.encode()
        self.base_frame = model.base_frame.encode()
        self._odometry = encode.odometry_struct(self.odom_frame, self.base_frame).pack
        self._covariance = struct.pack("<36d", *_COVARIANCE)
        self._frames = (len(self.odom_frame) + 1, self.odom_frame,
                        len(self.base_frame) + 1, self.base_frame)  # fmt: skip
        self.odom_key = ((self.odom_frame, self.base_frame),)
        # a message of zeros with the frames and covariances in place: a tick writes the stamp,
        # the pose's x, y, qz, qw and the twist's forward and turn speeds into it and copies it
        pose = encode.odometry_struct(self.odom_frame, self.base_frame).size - _ODOM_TAIL
        self._odometry_buffer = bytearray(self._odometry(
            encode.HEADER, 0, 0, *self._frames, *[0.0] * 7, self._covariance, *[0.0] * 6,
            self._covariance,
        ))  # fmt: skip
        self._odometry_offsets = (pose, pose + _ODOM_TWIST)
        self.joint_names = [j.encode() for j in model.joints]
        self._names = tuple(v for name in self.joint_names for v in (len(name) + 1, name))
        # joint states the same way: the joints the robot turns have values (the others none,
        # as the message object's arrays are the robot's lists cut to the names' count)
        robot = sim_robot.robot
        self.robot = robot
        names = tuple(self.joint_names)
        values = min(len(names), len(robot.wheels))
        self._whole = values == len(robot.wheels)  # the robot's lists go in as they are
        self._values = values
        self._joint_buffer = bytearray(encode.joint_struct(names, values).pack(
            encode.HEADER, 0, 0, 1, b"", len(names), *self._names,
            values, *[0.0] * values, values, *[0.0] * values, 0,
        ))  # fmt: skip
        positions, velocities = encode.joint_offsets(names, values)
        # the positions, the velocities' count and padding, the velocities: one pack_into
        gap = velocities - positions - 8 * values - 4
        self._joint_values_into = (
            struct.Struct(f"<{values}dI{gap}x{values}d").pack_into if values else None
        )
        self._joint_offset = positions
        index = {joint: k for k, joint in enumerate(model.joints)}
        self.wheels = [
            (frame.parent.encode(), frame.name.encode(), frame.xyz, quaternion(*frame.rpy),
             index.get(frame.joint))
            for frame in model.frames
            if frame.joint is not None
        ]  # fmt: skip
        self.wheel_key = tuple((parent, child) for parent, child, *_ in self.wheels)
        turning = len(sim_robot.robot.wheels)  # the joints the robot turns (the others: 0)
        self._wheel_heads = [  # the frames and offset, the fixed rotation, the joint turning it
            ((len(parent) + 1, parent, len(child) + 1, child, *xyz), rotation,
             joint if joint is not None and joint < turning else None)
            for parent, child, xyz, rotation, joint in self.wheels
        ]  # fmt: skip
        self.scans = {
            lidar: (lidar.frame_id.encode(),
                    (lidar.angle_min, lidar.angle_max, lidar_cast.increment(lidar), 0.0,
                     1.0 / lidar.rate, lidar.range_min, lidar.range_max))
            for lidar in model.lidars
        }  # fmt: skip

    def odometry(
        self, now_ns: int, odom: tuple[tuple[float, float, float], tuple[float, float]]
    ) -> bytes:
        """nav_msgs/Odometry of ``odom`` (the robot's :meth:`odometry`) as CDR."""
        (x, y, yaw), (forward, turn) = odom
        sec, nanosec = divmod(now_ns, NS)
        covariance = self._covariance
        return self._odometry(
            encode.HEADER, sec, nanosec, *self._frames,
            x, y, 0.0, 0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2), covariance,
            forward, 0.0, 0.0, 0.0, 0.0, turn, covariance,
        )  # fmt: skip

    def odometry_at(self, sec: int, nanosec: int, tf: list[object], message: bool) -> bytes:
        """The robot's odometry now as nav_msgs/Odometry CDR (b"" unless ``message``).

        Its ``odom -> base`` transform's values are added to ``tf``.
        """
        return self.tick_at(sec, nanosec, tf, MESSAGE if message else TRANSFORM, NOT_DUE)[0]

    def tick_at(
        self, sec: int, nanosec: int, tf: list[object], odometry: int, wheels: int
    ) -> tuple[bytes, bytes]:
        """A tick's odometry and wheels in one call: their messages (b"" where none).

        Each of ``odometry`` and ``wheels`` is :data:`NOT_DUE`, :data:`TRANSFORM` (its
        transforms' values are added to ``tf``: ``odom -> base``, then the wheel links) or
        :data:`MESSAGE` (its message too: nav_msgs/Odometry, sensor_msgs/JointState). The
        sim node's tick, where both fall due together, so calls this once per robot.
        """
        odom = joints = b""
        if odometry:
            x, y, yaw, forward, turn = self.robot.odometry_values()
            half = yaw / 2  # quaternion(0, 0, yaw)
            qz, qw = math.sin(half), math.cos(half)
            tf += (sec, nanosec)  # (three extends: no tuple built around the frames)
            tf += self._frames
            tf += (x, y, 0.0, 0.0, 0.0, qz, qw)
            if odometry == MESSAGE:
                buffer = self._odometry_buffer
                pose, twist = self._odometry_offsets
                _STAMP_INTO(buffer, 4, sec, nanosec)  # after the encapsulation header
                _POSE_INTO(buffer, pose, x, y, qz, qw)
                _TWIST_INTO(buffer, twist, forward, turn)
                odom = bytes(buffer)
        if wheels:
            robot = self.robot
            angles = robot.wheels
            for head, (ax, ay, az, aw), joint in self._wheel_heads:
                # multiply(rotation, a turn about z), written out: the same operations in the
                # same order as wheel_transforms', so the same numbers
                if joint is not None and (spin := angles[joint]):
                    bz, bw = math.sin(spin / 2), math.cos(spin / 2)
                    tf += (
                        sec, nanosec, *head,
                        aw * 0.0 + ax * bw + ay * bz - az * 0.0,
                        aw * 0.0 - ax * bz + ay * bw + az * 0.0,
                        aw * bz + ax * 0.0 - ay * 0.0 + az * bw,
                        aw * bw - ax * 0.0 - ay * 0.0 - az * bz,
                    )  # fmt: skip
                else:
                    tf += (sec, nanosec, *head, ax, ay, az, aw)
            if wheels == MESSAGE:
                buffer = self._joint_buffer
                _STAMP_INTO(buffer, 4, sec, nanosec)
                values_into = self._joint_values_into  # (None: no joint the robot turns)
                if values_into is not None and self._whole:
                    values_into(buffer, self._joint_offset, *angles, self._values,
                                *robot.wheel_rates)  # fmt: skip
                elif values_into is not None:
                    count = self._values
                    values_into(buffer, self._joint_offset, *angles[:count], count,
                                *robot.wheel_rates[:count])  # fmt: skip
                joints = bytes(buffer)
        return odom, joints

    def odom_transform(self, odom: tuple[tuple[float, float, float], object]) -> Transform:
        """``odom -> base_footprint`` of ``odom`` (the robot's :meth:`odometry`)."""
        x, y, yaw = odom[0]
        half = yaw / 2  # quaternion(0, 0, yaw)
        return (
            self.odom_frame, self.base_frame,
            (x, y, 0.0, 0.0, 0.0, math.sin(half), math.cos(half)),
        )  # fmt: skip

    def wheel_transforms(self) -> list[Transform]:
        """The wheel links turned by their joints."""
        angles = self.sim_robot.robot.wheels
        transforms: list[Transform] = []
        for parent, child, xyz, rotation, joint in self.wheels:
            spin = 0.0 if joint is None or joint >= len(angles) else angles[joint]
            if spin:
                rotation = multiply(rotation, (0.0, 0.0, math.sin(spin / 2), math.cos(spin / 2)))
            transforms.append((parent, child, (*xyz, *rotation)))
        return transforms

    def wheels_at(self, sec: int, nanosec: int, tf: list[object]) -> None:
        """The wheel links turned by their joints: their transforms' values added to ``tf``.

        The same numbers as :meth:`wheel_transforms` (its quaternion product, written out
        for a turn about z, with the same operations in the same order).
        """
        self.tick_at(sec, nanosec, tf, NOT_DUE, TRANSFORM)

    def joint_states(self, now_ns: int) -> bytes:
        """sensor_msgs/JointState of the wheels as CDR."""
        return self.joint_states_at(*divmod(now_ns, NS))

    def joint_states_at(self, sec: int, nanosec: int) -> bytes:
        """sensor_msgs/JointState of the wheels as CDR, stamped ``sec``, ``nanosec``."""
        return self.tick_at(sec, nanosec, [], NOT_DUE, MESSAGE)[1]

    def laser_scan(self, lidar: Lidar, ranges: np.ndarray, now_ns: int) -> bytes:
        """sensor_msgs/LaserScan of one of the robot's LiDARs as CDR."""
        frame, fields = self.scans[lidar]
        return encode.laser_scan(now_ns, frame, fields, ranges)

    def scan_packer(self, lidar: Lidar) -> encode.ScanPacker:
        """The packer of one of the robot's LiDARs' scans: (sec, nanosec, ranges) -> CDR."""
        return encode.ScanPacker(*self.scans[lidar])


def odometry_bytes(sim_robot: SimRobot, now_ns: int) -> bytes:
    """nav_msgs/Odometry as CDR (same as :func:`odometry`)."""
    return RobotEncoder(sim_robot).odometry(now_ns, sim_robot.robot.odometry())


def odom_transform(sim_robot: SimRobot) -> Transform:
    """``odom -> base_footprint`` for :func:`tf_bytes` (same as :func:`odom_tf`)."""
    return RobotEncoder(sim_robot).odom_transform(sim_robot.robot.odometry())


def wheel_transforms(sim_robot: SimRobot) -> list[Transform]:
    """The wheel links turned by their joints for :func:`tf_bytes` (same as :func:`wheel_tf`)."""
    return RobotEncoder(sim_robot).wheel_transforms()


def tf_bytes(transforms: list[Transform], now_ns: int) -> bytes:
    """tf2_msgs/TFMessage of the given transforms as CDR."""
    return encode.tf_message(now_ns, transforms)


def joint_states_bytes(sim_robot: SimRobot, now_ns: int) -> bytes:
    """sensor_msgs/JointState as CDR (same as :func:`joint_states`)."""
    return RobotEncoder(sim_robot).joint_states(now_ns)


def laser_scan_bytes(lidar: Lidar, ranges: np.ndarray, now_ns: int) -> bytes:
    """sensor_msgs/LaserScan as CDR (same as :func:`laser_scan`)."""
    fields = (lidar.angle_min, lidar.angle_max, lidar_cast.increment(lidar), 0.0,
              1.0 / lidar.rate, lidar.range_min, lidar.range_max)  # fmt: skip
    return encode.laser_scan(now_ns, lidar.frame_id.encode(), fields, ranges)
