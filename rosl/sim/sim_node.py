"""The sim node: a :class:`Simulation` on the bus, paced, free-running or in lock-step.

It publishes ``/clock`` at ``clock_rate`` Hz of sim time (10 by default, as gazebo_ros's
``publish_rate``, which counts wall time; at or above the physics rate: every step) and on
every step that publishes sensor data, so a subscriber's time is never behind a stamp it has
received; per robot odometry with ``odom -> base_footprint`` on ``/tf``, joint states (and
the wheels on ``/tf``, as robot_state_publisher would), scans, and once (transient local)
``/tf_static``, ``robot_description`` and the world's geometry on ``/world_markers``; it
drives each robot from its ``cmd_vel``. A topic nobody subscribes to is not computed nor
sent (except ``/clock``): skipping it changes nothing else that is published.

Modes: paced at ``real_time_factor`` x wall time (default 1); ``fast``: lock-step (see
:mod:`rosl.node.lockstep`) - each step's messages are handled by the controllers before the
next step, so the run does not depend on the machine's speed. Within a step the sensor
messages go out before ``/clock``, so a timer woken by the new time sees the step's data.
With ``record``, an in-process recorder writes the bus to MCAP with sim-time log times.

Paced (and not recording), the high-rate topics coalesce (``rosl/bus/coalesce.py``): a step's
messages wait in their topic's list, which this thread publishes as one batch before it sleeps
(sensors first, ``/clock`` last; no timer thread contends for the GIL) and, when it never
sleeps (running flat out, above what the pace asks), every eight milliseconds of wall time; the
bus is looked at (cmd_vel, parameters) before each wait and, flat out, every two milliseconds,
rather than every step: a datagram, or even a publish call, per step per topic would cost more
than the physics, and each flush (framing, MACs, a send per batch) and each look at the bus
has a fixed cost of tens of microseconds, which a longer interval spreads over more steps.
Lock-step and recording keep one datagram per message and serve the bus every step.
"""

from __future__ import annotations

import functools
import math
import operator
import sys
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from rosl.graph.records import SUBSCRIPTION
from rosl.sim import encode
from rosl.sim import messages as build
from rosl.sim.messages import MESSAGE, NOT_DUE, TRANSFORM
from rosl.sim.report import RobotReport, SimReport
from rosl.sim.simulation import Schedule

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from rosl.bag.recorder import Recorder
    from rosl.node.lockstep import LockstepSource
    from rosl.node.node import Node
    from rosl.node.publisher import Publisher
    from rosl.sim.encode import ScanPacker
    from rosl.sim.options import SimOptions
    from rosl.sim.simulation import SimRobot, Simulation
    from rosl.sim.worldfile import Lidar

NS = 1_000_000_000
SERVE_EVERY_S = 0.002  # paced, flat out: wall seconds between looks at the bus (cmd_vel, ...)
FLUSH_EVERY_S = 0.008  # paced, flat out: wall seconds between sends of the batches
# paced: a topic's batch bound, a datagram's size (the bus caps it there): 8 ms of odometry at
# 700x real time (~170 of 736 bytes) go in three
HELD_BYTES = 65000
_DUE = operator.attrgetter("at_ns")  # a schedule's next due time


class _Topic:
    """A publisher that is only fed while someone subscribes (or always, when forced)."""

    def __init__(self, sim_node: SimNode, publisher: Publisher, always: bool = False) -> None:
        self.sim_node = sim_node
        self.publisher = publisher
        self.always = always or sim_node._publish_all
        self._publish = publisher.publish
        self._publish_all = publisher.publish_all
        self._pending: list[bytes] = []

    def wanted(self) -> bool:
        return self.always or self.sim_node.subscribed(self.publisher.topic)

    def send(self, message: Any) -> None:
        self._publish(message)
        lockstep = self.sim_node.lockstep
        if lockstep is not None:
            lockstep.published(self.publisher)

    def free(self) -> None:
        """No lock-step: sending is publishing, one call less per message."""
        self.send = self._publish  # type: ignore[method-assign,assignment]

    def queue(self) -> None:
        """Batched: messages wait in a list until :meth:`flush` publishes them all at once."""
        self.publisher.hold_until_flush(HELD_BYTES)
        self.send = self._pending.append  # type: ignore[method-assign,assignment]

    def flush(self) -> None:
        """Publish what waits as the publisher's batch, and send it (its only messages)."""
        pending = self._pending
        if pending:
            self._publish_all(pending, flush=True)
            pending.clear()


@dataclass(slots=True)
class _RobotTopics:
    sim_robot: SimRobot
    odom: _Topic
    joints: _Topic | None
    scans: list[_Topic]
    description: Publisher
    encoder: build.RobotEncoder
    # each LiDAR with its schedule, topic and packer (see RobotEncoder.scan_packer)
    lidars: list[tuple[Lidar, Schedule, _Topic, ScanPacker]] = field(default_factory=list)
    odom_key: int = 0  # this robot's odometry transform in a tick's /tf (see SimNode._tf_pack)
    wheel_key: int = 0  # and its wheels'
    # the joint states at the odometry's rate: both schedules fall due at the same ticks and
    # fire alike from the same start, so the joints' takes the odometry's firing
    twin: bool = False


class SimNode:
    """Runs a simulation as the node ``sim``."""

    def __init__(
        self,
        sim: Simulation,
        node: Node,
        options: SimOptions,
        *,
        publish_all: bool = False,
        log: Callable[[str], None] | None = None,
    ) -> None:
        from geometry_msgs.msg import Twist

        from rosl.node.qos import DurabilityPolicy, QoSProfile, qos_profile_sensor_data

        self.sim = sim
        self.node = node
        from rosl.executor import SingleThreadedExecutor

        self.executor = SingleThreadedExecutor(context=node.context)  # /cmd_vel, parameters
        self.executor.answers_lockstep = False  # the simulator is the one waiting for answers
        self.executor.add_node(node)
        self.options = options
        self._log = log or (lambda line: print(line, file=sys.stderr, flush=True))
        self.lockstep: LockstepSource | None = None
        self.recorder: Recorder | None = None
        self._publish_all = publish_all
        self._counts: dict[str, int] = {}
        self._generation = -1
        self._warned: dict[str, int] = {}
        self._told: dict[int, int] = {}  # id(writer) -> last sequence number the recorder saw
        self._next_event = 0.0  # sim ns of the next firing of a sensor, odometry or /clock
        self._clock_schedule = Schedule(options.clock_rate)
        self._schedules = [self._clock_schedule] + [
            schedule
            for r in sim.robots
            for schedule in (r.odom, r.joints, *(s for _, s in r.lidars))
            if schedule is not None
        ]
        node.get_clock().set_sim_time(True)  # the sim's own stamps (its /rosout) are sim time
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self._batched = not options.fast and options.record is None
        self._flushed: list[_Topic] = []  # batched: the sensors' topics first, /clock last
        self.clock = _Topic(
            self,
            node.create_publisher(build.msg("rosgraph_msgs/msg/Clock"), "/clock", 10),
            always=True,
        )
        self.tf = _Topic(
            self,
            node.create_publisher(build.msg("tf2_msgs/msg/TFMessage"), "/tf", 100),
        )
        self.tf_static = node.create_publisher(
            build.msg("tf2_msgs/msg/TFMessage"), "/tf_static", latched
        )
        self.markers = node.create_publisher(
            build.msg("visualization_msgs/msg/MarkerArray"), "/world_markers", latched
        )
        self.robots: list[_RobotTopics] = []
        for sim_robot in sim.robots:
            spec = sim_robot.robot.spec
            model = spec.model
            prefix = f"/{spec.namespace}" if spec.namespace else ""
            node.create_subscription(
                Twist, f"{prefix}/{model.cmd_vel}", self._on_cmd_vel(sim_robot), 10
            )
            odom = _Topic(
                self,
                node.create_publisher(
                    build.msg("nav_msgs/msg/Odometry"),
                    f"{prefix}/{model.odom_topic}",
                    10,
                ),
            )
            joints = None
            if model.joint_states_topic:
                joints = _Topic(
                    self,
                    node.create_publisher(
                        build.msg("sensor_msgs/msg/JointState"),
                        f"{prefix}/{model.joint_states_topic}",
                        10,
                    ),
                )
            scans = [
                _Topic(
                    self,
                    node.create_publisher(
                        build.msg("sensor_msgs/msg/LaserScan"),
                        f"{prefix}/{lidar.topic}",
                        qos_profile_sensor_data,
                    ),
                )
                for lidar in model.lidars
            ]
            description = node.create_publisher(
                build.msg("std_msgs/msg/String"), f"{prefix}/robot_description", latched
            )
            topics = _RobotTopics(
                sim_robot, odom, joints, scans, description, build.RobotEncoder(sim_robot)
            )
            topics.lidars = [
                (lidar, s, t, topics.encoder.scan_packer(lidar))
                for (lidar, s), t in zip(sim_robot.lidars, scans, strict=True)
            ]
            topics.odom_key, topics.wheel_key = 2 * len(self.robots), 2 * len(self.robots) + 1
            joints_schedule = sim_robot.joints
            topics.twin = joints_schedule is not None and (
                (joints_schedule.rate, joints_schedule.index)
                == (sim_robot.odom.rate, sim_robot.odom.index)
            )
            self.robots.append(topics)
        self._tf_packs: dict[tuple[int, ...], Callable[..., bytes]] = {}
        self._clock_pack = functools.partial(encode.CLOCK.pack, encode.HEADER)  # (sec, nanosec)

    # --- bus helpers -------------------------------------------------------------------------

    def subscribed(self, topic: str) -> bool:
        """Whether anything (a node, a recorder) subscribes to ``topic``."""
        if self._publish_all:
            return True
        graph = self.node.participant.graph
        if graph.generation != self._generation:
            self._generation = graph.generation
            self._counts = {}
            for _, endpoint in graph.endpoints(SUBSCRIPTION):
                self._counts[endpoint.name] = self._counts.get(endpoint.name, 0) + 1
        return self._counts.get(topic, 0) > 0

    def _on_cmd_vel(self, sim_robot: SimRobot) -> Callable[[Any], None]:
        def take(message: Any) -> None:
            warning = sim_robot.robot.command(message.linear.x, message.angular.z)
            if warning is not None:
                self._warn(f"{sim_robot.name}: {warning}")

        return take

    def _logger(self) -> Any:
        """The node's logger, its clock moved to the current sim time (for /rosout stamps)."""
        self.node.get_clock().set_sim_now(self.sim.now_ns)
        return self.node.get_logger()

    def _warn(self, text: str) -> None:
        kind = text.split("(")[0]
        self._warned[kind] = self._warned.get(kind, 0) + 1
        if self._warned[kind] == 1:  # once per kind; the summary counts the rest
            self._logger().warn(f"{text}; further ones are counted, not shown")

    # --- publishing --------------------------------------------------------------------------

    def publish_static(self) -> None:
        """``/tf_static``, each robot's description and the world's markers (transient local)."""
        now = self.sim.now_ns
        self.tf_static.publish(build.static_tf(self.sim.world, now))
        self.markers.publish(build.world_markers(self.sim.world, now))
        for topics in self.robots:
            topics.description.publish(build.robot_description(topics.sim_robot.robot.spec))

    def tick(self) -> None:
        """Publish what is due at the current sim time; ``/clock`` last."""
        sim = self.sim
        now = sim.now_ns
        if now < self._next_event:  # most steps: nothing is due, not even /clock
            return
        clock = self._clock_schedule
        if now >= clock.at_ns:
            clock.fire(now)
        sec, nanosec = divmod(now, NS)  # one stamp for the tick's messages
        sampled = False
        key: tuple[int, ...] = ()  # the transforms in the /tf message (see _tf_pack)
        values: list[object] = []  # and their values, each robot's added by its encoder
        for topics in self.robots:
            sim_robot = topics.sim_robot
            encoder = topics.encoder
            odom = sim_robot.odom
            odometry = wheels = NOT_DUE
            if now >= odom.at_ns:
                odom.fire(now)
                if not sampled:
                    sim.sample()
                    sampled = True
                topic = topics.odom
                odometry = MESSAGE if topic.always or topic.wanted() else TRANSFORM
                key += (topics.odom_key,)
            joints = sim_robot.joints
            states_topic = topics.joints
            if joints is not None and now >= joints.at_ns:
                if topics.twin:  # the odometry's firing, just taken: the same numbers
                    joints.index, joints.at_ns = odom.index, odom.at_ns
                else:
                    joints.fire(now)
                wheels = TRANSFORM
                if states_topic is not None and (states_topic.always or states_topic.wanted()):
                    wheels = MESSAGE
                key += (topics.wheel_key,)
            if odometry or wheels:  # one call for both (their messages, b"" where none)
                message, states = encoder.tick_at(sec, nanosec, values, odometry, wheels)
                if odometry == MESSAGE:
                    topics.odom.send(message)
                if states_topic is not None and wheels == MESSAGE:
                    states_topic.send(states)
            for lidar, schedule, topic, scan_bytes in topics.lidars:
                if now >= schedule.at_ns:
                    index = schedule.fire(now)
                    wanted = topic.always or topic.wanted()
                    if wanted or self.options.render is not None:
                        ranges = sim.scan(sim_robot, lidar, index)
                        if wanted:
                            topic.send(scan_bytes(sec, nanosec, ranges))
        tf = self.tf
        if key and (tf.always or tf.wanted()):  # one /tf message per tick, as a broadcaster
            pack = self._tf_packs.get(key) or self._tf_pack(key)
            tf.send(pack(*values))
        self.clock.send(self._clock_pack(sec, nanosec))  # every step's data too
        self._next_event = min(map(_DUE, self._schedules))

    def _tf_pack(self, key: tuple[int, ...]) -> Callable[..., bytes]:
        """The packer of /tf of these robots' odometry (2 k) and wheels (2 k + 1) transforms.

        It takes the transforms' values: the header and the count are bound.
        """
        frames: tuple[tuple[bytes, bytes], ...] = ()
        for part in key:
            encoder = self.robots[part // 2].encoder
            frames += encoder.wheel_key if part % 2 else encoder.odom_key
        pack = functools.partial(encode.tf_struct(frames).pack, encode.HEADER, len(frames))
        self._tf_packs[key] = pack
        return pack

    # --- running -----------------------------------------------------------------------------

    def run(self) -> SimReport:
        """Run until the duration is reached or the context shuts down; return the report."""
        from rosl.node.lockstep import LockstepSource

        options = self.options
        participant = self.node.participant
        if options.record is not None:
            self._start_recorder(options.record)
        if options.fast:
            self.lockstep = LockstepSource(
                participant,
                timeout=options.lockstep_timeout,
                on_stall=options.on_stall,
                log=lambda line: self._logger().warn(line),
            )
            for topic in self._stepped():
                self.lockstep.mark(topic.publisher)
        else:
            for topic in self._stepped():
                topic.free()
        if self._batched:
            for topic in self._stepped():
                topic.queue()
            self._flushed = list(reversed(self._stepped()))
        self.publish_static()
        self._announce()
        self._wait_for_peers()
        if self.recorder is not None:  # the static messages, but nothing sent before the start
            self.recorder.record_at(0, lambda: True, only_from=participant.sender)
            self._own_sent()
        end_ns = None if options.duration is None else round(options.duration * NS)
        context = self.node.context
        started = time.monotonic()
        status_at = started + 1.0
        live = not options.headless and sys.stderr.isatty()
        self.tick()
        if self._batched:
            self._run_paced(started, end_ns, live)
        else:
            sim, tick, settle = self.sim, self.tick, self._settle
            while context.ok():
                settle()
                if end_ns is not None and sim.now_ns >= end_ns:
                    break
                if not options.fast:
                    self._pace(started)
                sim.step()
                tick()
                if live and time.monotonic() >= status_at:
                    status_at += 1.0
                    self._status(started)
        self._flush()  # what the batches still hold
        wall = time.monotonic() - started
        if live:
            sys.stderr.write("\n")
        return self._finish(wall)

    def _run_paced(self, started: float, end_ns: int | None, live: bool) -> None:
        """The paced loop: the bus, its batches, Ctrl-C and the status line.

        When the loop never waits (flat out), the bus is looked at every
        :data:`SERVE_EVERY_S` and the batches go out every :data:`FLUSH_EVERY_S`; when it
        waits, both happen before each wait, and the bus is served throughout (see
        :meth:`_pace`).
        """
        sim, tick, step, step_ns = self.sim, self.tick, self.sim.step, self.sim.step_ns
        advance = sim.advance
        context, monotonic = self.node.context, time.monotonic
        scale = NS * self.options.real_time_factor  # sim ns per wall second
        end = math.inf if end_ns is None else end_ns
        status_at = started + 1.0
        serve_at = flush_at = 0.0
        while True:
            wall = monotonic()
            if wall >= serve_at:
                if wall >= flush_at:
                    self._flush()
                    flush_at = wall + FLUSH_EVERY_S
                if not context.ok():
                    return
                self.executor.spin_some()  # /cmd_vel, parameters
                serve_at = wall + SERVE_EVERY_S
                if live and wall >= status_at:
                    status_at += 1.0
                    self._status(started)
            now = sim.now_ns
            if now >= end:
                return
            allowed = (wall - started) * scale - step_ns  # the last start the pace allows now
            if now > allowed:
                self._pace(started)
                step()
            else:  # the steps that publish nothing run back to back, the clock unread
                advance(min(self._next_event, end), allowed)
            if sim.now_ns >= self._next_event:
                tick()

    def _flush(self) -> None:
        """Paced: send what the batches hold, the sensors' first and ``/clock`` last."""
        if self._batched:
            for topic in self._flushed:
                topic.flush()

    def _stepped(self) -> list[_Topic]:
        """The topics published as the simulation steps."""
        return [self.clock, self.tf] + [
            t for r in self.robots for t in (r.odom, r.joints, *r.scans) if t
        ]

    def _settle(self) -> None:
        """After a step's messages went out: wait (lock-step) and record."""
        replies: list[tuple[int, int, int, int]] = []
        if self.lockstep is not None:
            replies = self.lockstep.wait(self.sim.now_ns)
            self.lockstep.settle(replies)
        self.executor.spin_some()  # the replies (a /cmd_vel) act before the next step
        recorder = self.recorder
        participant = recorder.participant if recorder is not None else None
        if recorder is not None and participant is not None:
            own = self._own_sent()
            expected = [*replies, *own]
            lockstep = self.lockstep
            check = (
                (lambda: lockstep.caught_up(participant, expected))
                if (lockstep is not None)
                else None
            )
            recorder.record_at(self.sim.now_ns, check)

    def _own_sent(self) -> list[tuple[int, int, int, int]]:
        """The sim's own messages sent since the last call (the recorder must have them)."""
        participant = self.node.participant
        sent = []
        for writer in participant.writers:
            if writer.last_seq != self._told.get(id(writer), 0):
                self._told[id(writer)] = writer.last_seq
                sent.append((participant.sender, writer.topic, writer.endpoint, writer.last_seq))
        return sent

    def _pace(self, started: float) -> None:
        """Real-time factor pacing: serve the bus until the next step is due in wall time."""
        factor = self.options.real_time_factor
        due = started + (self.sim.now_ns + self.sim.step_ns) / NS / factor
        flushed = False
        while self.node.context.ok():
            remaining = due - time.monotonic()
            if remaining <= 0:
                return
            if not flushed:  # about to wait: what the batches hold goes out now
                self._flush()
                flushed = True
            self.executor.spin_once(remaining)

    def _wait_for_peers(self) -> None:
        """Lock-step: start when the named nodes (or a publisher of each cmd_vel) are up."""
        if self.lockstep is None:
            return
        graph = self.node.participant.graph
        names = [n if n.startswith("/") else f"/{n}" for n in self.options.wait_for]
        cmd_topics = [
            (f"/{t.sim_robot.robot.spec.namespace}" if t.sim_robot.robot.spec.namespace else "")
            + f"/{t.sim_robot.robot.spec.model.cmd_vel}"
            for t in self.robots
        ]

        def ready() -> bool:
            answering = {p.sender for p in graph.processes() if p.lockstep}
            if names:
                up = {n.fqn for n in graph.nodes() if n.process in answering}
                return all(name in up for name in names)
            from rosl.graph.records import PUBLISHER

            return all(
                any(node.process in answering for node, _ in graph.endpoints(PUBLISHER, topic))
                for topic in cmd_topics
            )

        if ready():
            return
        what = ", ".join(names) if names else "a node publishing " + ", ".join(cmd_topics)
        limit = f"{self.options.startup_timeout:g} s"
        self._log(f"[INFO] [sim]: lock-step: waiting for {what} (up to {limit})")  # not /rosout
        deadline = time.monotonic() + self.options.startup_timeout
        while not ready() and time.monotonic() < deadline and self.node.context.ok():
            self.executor.spin_some(0.05)
        if not ready():
            self._log(
                f"[WARN] [sim]: lock-step: {what} did not come up in "
                f"{self.options.startup_timeout:g} s; starting without it"
            )

    def _start_recorder(self, folder: Path) -> None:
        from rosl.bag.recorder import Recorder

        def log(line: str) -> None:
            if not line.startswith("[INFO]"):
                self._log(line)

        participant = self.node.participant
        self._told = {id(w): w.last_seq for w in participant.writers}  # before the recorder
        self.recorder = Recorder(
            folder,
            domain=self.node.participant.transport.domain,
            compression="zstd",
            log=log,
        )
        self.recorder.start()

    def _announce(self) -> None:
        """One line on stderr when the world is up: the robots, their topics, the pace."""
        options = self.options
        pace = "lock-step" if options.fast else f"paced at {options.real_time_factor:g}x real time"
        lines = []
        for topics in self.robots:
            spec = topics.sim_robot.robot.spec
            prefix = f"/{spec.namespace}" if spec.namespace else ""
            out = " ".join(
                t.publisher.topic for t in (topics.odom, topics.joints, *topics.scans) if t
            )
            lines.append(f"{spec.name} drives on {prefix}/{spec.model.cmd_vel}, publishes {out}")
        robots = "; ".join(lines)
        until = f"for {options.duration:g} s" if options.duration is not None else "Ctrl-C to stop"
        self._log(
            f"[sim] {self.sim.world.name} is up ({pace}, {until}): {robots}; "
            "and /tf /tf_static /clock"
        )

    def _status(self, started: float) -> None:
        wall = time.monotonic() - started
        sim_s = self.sim.now_ns / NS
        sys.stderr.write(f"\r[sim] t={sim_s:8.2f} s  {sim_s / wall if wall else 0:6.1f}x real time")
        sys.stderr.flush()

    def _finish(self, wall: float) -> SimReport:
        options = self.options
        recorded: dict[str, int] = {}
        if self.recorder is not None:
            self.recorder.close()
            recorded = {
                name: t.info.count for name, t in self.recorder._topics.items() if t.info.count
            }
        mode = "lock-step" if options.fast else f"paced at {options.real_time_factor:g}x"
        report = SimReport(
            world=self.sim.world.name,
            sim_seconds=self.sim.now_ns / NS,
            wall_seconds=wall,
            mode=mode,
            robots=[
                RobotReport(r.name, r.distance, r.closest, r.collisions, r.robot.pose)
                for r in self.sim.robots
            ],
            recorded=recorded,
            bag=options.record,
            stalls=self.lockstep.stalls if self.lockstep is not None else 0,
            warnings=[f"{kind.strip()}: {count} time(s)" for kind, count in self._warned.items()],
        )
        if options.render is not None:
            from rosl.sim.render import render_simulation

            report.picture = render_simulation(self.sim, options.render)
        return report
