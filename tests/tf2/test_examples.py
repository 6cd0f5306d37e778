"""Programs written like geometry2's examples_tf2_py, each its own process, talking over the bus.

Each is an executable of a workspace package started with ``rosl run``. A static broadcaster, a dynamic (turtle-like) broadcaster stamping with the clock, a frame
listener blocking in ``lookup_transform(..., timeout=...)`` inside a timer callback of a
single-threaded ``rclpy.spin``, one awaiting ``lookup_transform_async`` and
``wait_for_transform_async`` in a coroutine callback, and one whose listener spins its own
thread while the main thread blocks.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import pytest

from tests.graph.support import Watched

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.conftest import Processes

MAIN = """

def main():
    rclpy.init()
    node = {node}()
    print('ready', flush=True)
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
"""

STATIC_BROADCASTER = """
import math
import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros.static_transform_broadcaster import StaticTransformBroadcaster


def make(parent, child, x, y, yaw, stamp):
    t = TransformStamped()
    t.header.stamp = stamp
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x = x
    t.transform.translation.y = y
    t.transform.rotation.z = math.sin(yaw / 2)
    t.transform.rotation.w = math.cos(yaw / 2)
    return t


class StaticFramePublisher(Node):
    def __init__(self):
        super().__init__('static_broadcaster')
        self.broadcaster = StaticTransformBroadcaster(self)
        now = self.get_clock().now().to_msg()
        self.broadcaster.sendTransform(make('turtle1', 'sonar_2', 0.5, 0.0, math.pi / 2, now))
        self.broadcaster.sendTransform(make('turtle1', 'starboard_wheel', 0.0, -0.3, 0.0, now))


""" + MAIN.format(node="StaticFramePublisher")

TURTLE_BROADCASTER = """
import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from tf2_ros import TransformBroadcaster


class TurtleBroadcaster(Node):
    def __init__(self):
        super().__init__('turtle_broadcaster')
        self.tf_broadcaster = TransformBroadcaster(self)
        self.create_timer(0.05, self.on_pose)

    def on_pose(self):
        t = TransformStamped()
        t.header.stamp = self.get_clock().now().to_msg()
        t.header.frame_id = 'world'
        t.child_frame_id = 'turtle1'
        t.transform.translation.x = 4.0
        t.transform.translation.y = 2.0
        t.transform.rotation.w = 1.0
        self.tf_broadcaster.sendTransform(t)


""" + MAIN.format(node="TurtleBroadcaster")

BLOCKING_LISTENER = """
import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
import rclpy.time
from tf2_ros import TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener


class FrameListener(Node):
    def __init__(self):
        super().__init__('frame_listener')
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.timer = self.create_timer(0.2, self.on_timer)

    def on_timer(self):
        self.timer.cancel()  # one look: it blocks this single-threaded executor until it has it
        try:
            t = self.tf_buffer.lookup_transform(
                'world', 'sonar_2', rclpy.time.Time(), timeout=Duration(seconds=60.0))
        except TransformException as ex:
            print(f'not yet: {ex}', flush=True)
            return
        v, q = t.transform.translation, t.transform.rotation
        print(f'sonar_2 in world: {v.x:.3f} {v.y:.3f} {v.z:.3f} {q.z:.3f} {q.w:.3f} '
              f'stamped={t.header.stamp.sec > 0} frames={t.header.frame_id},{t.child_frame_id}',
              flush=True)


""" + MAIN.format(node="FrameListener")

ASYNC_LISTENER = """
import rclpy
import rclpy.time
from rclpy.node import Node
from tf2_ros import LookupException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener


class AsyncWaitsForTransform(Node):
    def __init__(self):
        super().__init__('async_waits_for_transform')
        self._tf_buffer = Buffer()
        self._tf_listener = TransformListener(self._tf_buffer, self)
        self._output_timer = self.create_timer(0.5, self.on_timer)

    async def on_timer(self):
        when = rclpy.time.Time()
        try:
            transform = await self._tf_buffer.lookup_transform_async(
                'starboard_wheel', 'sonar_2', when)
            waited = await self._tf_buffer.wait_for_transform_async('world', 'sonar_2', when)
        except LookupException as e:
            print(f'failed: {e!r}', flush=True)
            return
        v, w = transform.transform.translation, waited.transform.translation
        print(f'got {v.x:.3f} {v.y:.3f} then {w.x:.3f} {w.y:.3f}', flush=True)


""" + MAIN.format(node="AsyncWaitsForTransform")

THREADED_LISTENER = """
import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.time import Time
from tf2_ros import Buffer, TransformListener



def main():
    rclpy.init()
    node = Node('threaded_listener')
    buffer = Buffer()
    listener = TransformListener(buffer, node, spin_thread=True)
    print('ready', flush=True)
    t = buffer.lookup_transform('turtle1', 'starboard_wheel', Time(), Duration(seconds=30.0))
    print(f'wheel in turtle1: {t.transform.translation.y:.3f}', flush=True)
    rclpy.shutdown()
"""


PROGRAMS = {
    "static_broadcaster": STATIC_BROADCASTER,
    "turtle_broadcaster": TURTLE_BROADCASTER,
    "frame_listener": BLOCKING_LISTENER,
    "async_waits_for_transform": ASYNC_LISTENER,
    "threaded_listener": THREADED_LISTENER,
}


@pytest.fixture
def examples(make_package: Callable[..., Path]) -> None:
    """A workspace package ``examples_tf2`` with the programs as its executables."""
    executables = "".join(
        f'<executable name="{name}">examples_tf2.{name}:main</executable>' for name in PROGRAMS
    )
    manifest = (
        '<?xml version="1.0"?>\n<package format="3">\n  <name>examples_tf2</name>\n'
        "  <version>0.0.0</version>\n  <depend>tf2_ros</depend>\n"
        f"  <export><rosl>{executables}</rosl></export>\n</package>\n"
    )
    files = {f"examples_tf2/{name}.py": code for name, code in PROGRAMS.items()}
    make_package("examples_tf2", {"examples_tf2/__init__.py": "", **files}, manifest)


def start(processes: Processes, name: str) -> Watched:
    child = Watched(processes.rosl("run", "examples_tf2", name))
    child.wait_ready()
    return child


def test_a_listener_blocking_in_its_timer_gets_the_transform_once_broadcasters_start(
    processes: Processes, examples: None
) -> None:
    listener = start(processes, "frame_listener")  # first: it has to wait for the frames
    start(processes, "static_broadcaster")
    start(processes, "turtle_broadcaster")
    assert listener.wait_for("^(sonar_2 in world|not yet)", timeout=90), listener.text("err")
    assert not listener.matching("^not yet"), listener.text()  # rclpy's would time out here
    line = listener.matching("^sonar_2 in world: (.*)")[0][1]
    # sonar_2 is 0.5 m ahead of turtle1 (at 4, 2), turned a quarter: z, w = sin, cos of 45°
    half = math.sqrt(0.5)
    assert line == f"4.500 2.000 0.000 {half:.3f} {half:.3f} stamped=True frames=world,sonar_2"


def test_a_coroutine_callback_awaits_the_transforms(processes: Processes, examples: None) -> None:
    start(processes, "static_broadcaster")
    listener = start(processes, "async_waits_for_transform")  # after: the static frames are latched
    start(processes, "turtle_broadcaster")
    assert listener.wait_for("^got ", timeout=60), listener.text("err")
    # sonar_2 seen from starboard_wheel: 0.5 ahead and 0.3 to the left of it
    assert listener.matching("^got (.*)")[0][1] == "0.500 0.300 then 4.500 2.000"
    assert not listener.matching("^failed")


def test_a_listener_with_its_own_spin_thread_serves_a_blocking_main_thread(
    processes: Processes, examples: None
) -> None:
    listener = start(processes, "threaded_listener")
    start(processes, "static_broadcaster")
    assert listener.wait_for("^wheel in turtle1", timeout=60), listener.text("err")
    assert listener.lines()[-1] == "wheel in turtle1: -0.300"
    assert listener.child.wait(timeout=30) == 0
