"""``tf2_monitor``: how late transforms arrive, per frame and per broadcaster, as tf2_monitor.

``tf2_monitor`` watches every frame; ``tf2_monitor FRAME_A FRAME_B`` waits for the chain
between the two and also tracks the net delay of looking up B in A. Every ~10 s (21 looks,
0.5 s apart) it prints tf2_monitor's report: the chain, each frame's average and maximum
delay (now minus the transform's stamp), and each broadcaster's rate and delays. Where
tf2_monitor prints ``<no authority available>``, rosl names the publishing node.
"""

from __future__ import annotations

import sys
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from rosl.graph.records import PUBLISHER
from rosl.tf2.errors import Tf2ArgumentError, TransformException
from rosl.tf2.program import run, spin_for, user_args

NO_AUTHORITY = "<no authority available>"
AUTHORITY_WAIT_S = 2.0  # how long a message of an unknown publisher waits for its name
KEPT = 1000  # samples kept per frame and per broadcaster
LOOK_EVERY_S = 0.5
LOOKS_PER_REPORT = 21
LOWPASS = 0.01


@dataclass(slots=True)
class Delays:
    """Recent delays (s) of one frame or broadcaster, and when its messages came (s)."""

    delays: deque[float] = field(default_factory=lambda: deque(maxlen=KEPT))
    arrivals: deque[float] = field(default_factory=lambda: deque(maxlen=KEPT))

    def average(self) -> float:
        """Mean delay."""
        return sum(self.delays) / len(self.delays) if self.delays else 0.0

    def maximum(self) -> float:
        """Largest delay (at least 0, as tf2_monitor counts it)."""
        return max([0.0, *self.delays])

    def rate(self) -> float:
        """Messages per second over the kept arrivals."""
        span = self.arrivals[-1] - self.arrivals[0] if self.arrivals else 0.0
        return len(self.arrivals) / max(1e-8, span)


@dataclass(slots=True)
class Tally:
    """What the monitor has seen: per frame, per broadcaster, and the chain's net delay."""

    frames: dict[str, Delays] = field(default_factory=dict)
    authority: dict[str, str] = field(default_factory=dict)
    broadcasters: dict[str, Delays] = field(default_factory=dict)
    chain: list[str] = field(default_factory=list)
    net_average: float = 0.0
    net_max: float = 0.0

    def add(self, message: Any, authority: str, now_s: float) -> None:
        """Count one TFMessage received at ``now_s`` from ``authority``."""
        total = 0.0
        for t in message.transforms:
            stamp = t.header.stamp.sec + t.header.stamp.nanosec * 1e-9
            self.authority[t.child_frame_id] = authority
            self.frames.setdefault(t.child_frame_id, Delays()).delays.append(now_s - stamp)
            total += now_s - stamp
        who = self.broadcasters.setdefault(authority, Delays())
        who.delays.append(total / max(1, len(message.transforms)))
        who.arrivals.append(now_s)

    def look(self, delay: float) -> None:
        """Fold one lookup's delay into the chain's net delay."""
        self.net_average = LOWPASS * delay + (1 - LOWPASS) * self.net_average
        self.net_max = max(self.net_max, delay)


def report(tally: Tally, frames: tuple[str, str] | None) -> tuple[str, str, str]:
    """tf2_monitor's report: (stdout text, the stderr heading, the broadcasters' lines)."""
    if frames is None:
        out = "\n\n\nRESULTS: for all Frames\n"
    else:
        out = (f"\n\n\nRESULTS: for {frames[0]} to {frames[1]}\n"
               f"Chain is: {' -> '.join(tally.chain)}\n"
               f"Net delay     avg = {tally.net_average:g}: max = {tally.net_max:g}\n")  # fmt: skip
    out += "\nFrames:\n"
    for frame in sorted(tally.frames):
        if frames is not None and frame not in tally.chain:
            continue
        d = tally.frames[frame]
        out += (f"Frame: {frame}, published by {tally.authority.get(frame, NO_AUTHORITY)}, "
                f"Average Delay: {d.average():g}, Max Delay: {d.maximum():g}\n")  # fmt: skip
    nodes = "".join(
        f"Node: {name} {d.rate():g} Hz, Average Delay: {d.average():g} Max Delay: {d.maximum():g}\n"
        for name, d in sorted(tally.broadcasters.items())
    )
    return out, "\nAll Broadcasters:\n", nodes


def parse(args: list[str]) -> tuple[str, str] | None:
    """The two frames, or None to watch all.

    Raises:
        Tf2ArgumentError: one frame, or more than two.
    """
    if not args:
        return None
    if len(args) != 2:
        raise Tf2ArgumentError("usage: tf2_monitor [FRAME_A FRAME_B] (two frames, or none)")
    return args[0], args[1]


def main(args: list[str] | None = None) -> int:
    """Run the program (``rosl run tf2_ros tf2_monitor [A B]``)."""
    frames = parse(user_args(args))
    return run(args, "tf2_monitor_main", lambda node: _run(node, frames))


def _run(node: Any, frames: tuple[str, str] | None) -> None:
    import rosl
    from rosl.tf2.buffer import Buffer
    from rosl.tf2.listener import TransformListener

    buffer = Buffer()
    node.tf_listener = TransformListener(buffer, node)
    tally = Tally()
    _subscribe(node, tally)
    executor = rosl.SingleThreadedExecutor()
    executor.add_node(node)
    if frames is not None:
        print(f"Waiting for transform chain to become available between {frames[0]} and "
              f"{frames[1]} ", end="", flush=True)  # fmt: skip
        while rosl.ok() and not buffer.can_transform(frames[0], frames[1], rosl.Time(), 1.0):
            print(".", end="", flush=True)
        print(flush=True)
        tally.chain = buffer.chain(frames[1], frames[0])
    looks = 0
    while rosl.ok():
        looks += 1
        if frames is not None:
            try:
                found = buffer.lookup_transform_core(frames[0], frames[1], rosl.Time())
                stamp = found.header.stamp.sec + found.header.stamp.nanosec * 1e-9
                tally.look(time.time() - stamp)
            except TransformException:
                pass
        spin_for(executor, LOOK_EVERY_S)
        if looks >= LOOKS_PER_REPORT:
            looks = 0
            out, heading, nodes = report(tally, frames)
            print(out, end="", flush=True)
            print(heading, end="", file=sys.stderr, flush=True)
            print(nodes, end="", flush=True)


def _subscribe(node: Any, tally: Tally) -> None:
    from rosl.idl.registry import get_message_class
    from rosl.node.qos import DurabilityPolicy, QoSProfile

    graph = node.participant.graph
    waited: set[tuple[int, int, str]] = set()  # publishers whose name was waited for
    tf_message: Any = get_message_class("tf2_msgs/msg/TFMessage")
    for topic, durability in (("/tf", DurabilityPolicy.VOLATILE),
                              ("/tf_static", DurabilityPolicy.TRANSIENT_LOCAL)):  # fmt: skip

        def heard(message: Any, info: dict[str, Any], topic: str = topic) -> None:
            gid = info.get("publisher_gid")
            found = None
            if gid:

                def known() -> bool:
                    return graph.sender(gid[0], gid[1], PUBLISHER, topic) is not None

                # a latched /tf_static message is replayed at once, maybe before the graph
                # has its publisher: give discovery a moment, once per publisher
                if (gid[0], gid[1], topic) not in waited and not known():
                    waited.add((gid[0], gid[1], topic))
                    graph.wait_for(known, AUTHORITY_WAIT_S)
                found = graph.sender(gid[0], gid[1], PUBLISHER, topic)
            tally.add(message, found[0].fqn if found else NO_AUTHORITY, time.time())

        node.create_subscription(tf_message, topic, heard,
                                 QoSProfile(depth=100, durability=durability))  # fmt: skip


__all__ = ["Delays", "Tally", "main", "parse", "report"]
