"""tf2 Buffer lookups per second vs composing the same transforms by hand.

A TurtleBot-like tree: map→odom and odom→base_footprint dynamic at 50 Hz for 10 s (500 stamps
each), base_footprint→base_link→base_scan static. Each lookup is map←base_scan at a time
between two stamps (so both dynamic edges interpolate) and comes out as a TransformStamped
message; the baseline multiplies four ready-made Transforms. The ratio is what the buffer's
walk, interpolation, validation and message building cost over the bare math.

    python bench/tf2_lookup.py [--lookups N]
"""

from __future__ import annotations

import argparse
import math
import time


def _stamped(parent: str, child: str, x: float, yaw: float, seconds: float) -> object:
    from rosl.idl.registry import get_message_class

    t = get_message_class("geometry_msgs/msg/TransformStamped")()
    t.header.frame_id, t.child_frame_id = parent, child
    t.header.stamp.sec, t.header.stamp.nanosec = divmod(round(seconds * 1e9), 1_000_000_000)
    t.transform.translation.x = x
    t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return t


def measure(lookups: int) -> tuple[float, float]:
    """(buffer lookups/s, hand compositions/s)."""
    from rosl.node.clock import Time
    from rosl.tf2.buffer import Buffer
    from rosl.tf2.transform import Transform

    buffer = Buffer()
    buffer.set_transform_static(_stamped("base_footprint", "base_link", 0.0, 0.0, 0), "b")
    buffer.set_transform_static(_stamped("base_link", "base_scan", -0.03, 0.0, 0), "b")
    for i in range(500):
        seconds = 100.0 + i * 0.02
        buffer.set_transform(_stamped("map", "odom", 0.001 * i, 0.0, seconds), "b")
        buffer.set_transform(_stamped("odom", "base_footprint", 0.01 * i, 0.002 * i, seconds), "b")
    times = [Time(seconds=100.0 + (i % 499) * 0.02 + 0.01) for i in range(lookups)]
    start = time.perf_counter()
    for when in times:
        buffer.lookup_transform_core("map", "base_scan", when)
    through_buffer = lookups / (time.perf_counter() - start)
    parts = [Transform((0.5, 0.0, 0.0), (0.0, 0.0, 0.1, math.sqrt(0.99)))] * 4
    start = time.perf_counter()
    for _ in range(lookups):
        parts[0] * parts[1] * parts[2] * parts[3]
    by_hand = lookups / (time.perf_counter() - start)
    return through_buffer, by_hand


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lookups", type=int, default=20_000)
    args = parser.parse_args()
    through_buffer, by_hand = measure(args.lookups)
    print(f"buffer lookups: {through_buffer:,.0f}/s; hand composition: {by_hand:,.0f}/s; "
          f"ratio {through_buffer / by_hand:.3f}")  # fmt: skip


if __name__ == "__main__":
    main()
