"""Unmodified rclpy scripts run under rosl and talk to rosl nodes; rclpy's names exist."""

from __future__ import annotations

import json
import signal

from tests.node.helpers import snippet, spin_until

RUN_AS_RCLPY = (
    "import rosl.compat; rosl.compat.install(force=True); import runpy, sys; "
    "runpy.run_path(sys.argv[1], run_name='__main__')"
)

RCLPY_TALKER = """
import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String


class Talker(Node):
    def __init__(self):
        super().__init__("rclpy_talker")
        qos = QoSProfile(
            depth=10,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.VOLATILE,
        )
        self.declare_parameter("greeting", "hello")
        self.publisher_ = self.create_publisher(String, "chatter", qos)
        self.subscription = self.create_subscription(String, "reply", self.on_reply, qos)
        self.timer = self.create_timer(0.05, self.timer_callback)
        self.i = 0

    def timer_callback(self):
        msg = String()
        msg.data = f"{self.get_parameter('greeting').value} {self.i}"
        self.publisher_.publish(msg)
        self.i += 1

    def on_reply(self, msg):
        self.get_logger().info(f"I heard: {msg.data}")
        print(f"reply: {msg.data}", flush=True)


def main(args=None):
    rclpy.init(args=args)
    node = Talker()
    print("spinning", flush=True)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    node.destroy_node()
    rclpy.shutdown()
    print("clean exit", flush=True)


if __name__ == "__main__":
    main()
"""


def _start(spawn, tmp_path, source, *args):
    script = tmp_path / "script.py"
    script.write_text(snippet(source))
    return spawn(RUN_AS_RCLPY, str(script), *args)


def test_an_unmodified_rclpy_script_talks_to_a_rosl_node(ros, spawn, tmp_path):
    from std_msgs.msg import String

    child = _start(spawn, tmp_path, RCLPY_TALKER, "--ros-args", "-p", "greeting:=bonjour")
    child.expect("^spinning$")
    node = ros.Node("rosl_side")
    heard: list[str] = []
    node.create_subscription(String, "chatter", lambda m: heard.append(m.data), 10)
    reply = node.create_publisher(String, "reply", 10)

    assert spin_until(node, lambda: bool(heard), 20.0)
    assert heard[0].startswith("bonjour ")
    assert spin_until(
        node,
        lambda: child.wait_for("^reply: from rosl$", timeout=0.0) is not None,
        20.0,
        each=lambda: reply.publish(String(data="from rosl")),
    )
    child.expect(r"\[INFO\] \[\d+\.\d{9}\] \[rclpy_talker\]: I heard: from rosl", stream="err")


def test_ctrl_c_ends_an_rclpy_script_with_exit_code_0_and_no_traceback(spawn, tmp_path):
    child = _start(spawn, tmp_path, RCLPY_TALKER)
    child.expect("^spinning$")
    child.popen.send_signal(signal.SIGINT)
    out, err = child.finish()

    assert child.returncode == 0, err
    assert "Traceback" not in err
    assert "KeyboardInterrupt" not in err
    assert out.rstrip().endswith("clean exit")


def test_sigterm_also_ends_an_rclpy_script_cleanly(spawn, tmp_path):
    child = _start(spawn, tmp_path, RCLPY_TALKER)
    child.expect("^spinning$")
    child.popen.send_signal(signal.SIGTERM)
    out, err = child.finish()

    assert child.returncode == 0, err
    assert "Traceback" not in err
    assert out.rstrip().endswith("clean exit")


NAMES = """
import json

import rclpy
import rclpy.qos as q
from rclpy.clock import Clock, ClockType
from rclpy.duration import Duration
from rclpy.exceptions import ParameterNotDeclaredException
from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
from rclpy.logging import LoggingSeverity, get_logger
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.task import Future
from rclpy.time import Time
from rclpy.utilities import remove_ros_args

import rosl

print(json.dumps({
    "node_is_rosl": Node is rosl.Node,
    "sensor_data": [q.qos_profile_sensor_data.depth, q.qos_profile_sensor_data.reliability.name],
    "services_default_depth": q.qos_profile_services_default.depth,
    "parameter_events_depth": q.qos_profile_parameter_events.depth,
    "system_default_history": q.qos_profile_system_default.history.name,
    "preset": q.QoSPresetProfiles.get_from_short_key("sensor_data").reliability.name,
    "reliability": [p.name for p in q.ReliabilityPolicy],
    "durability": [p.name for p in q.DurabilityPolicy],
    "history": [p.name for p in q.HistoryPolicy],
    "old_names": q.QoSReliabilityPolicy is q.ReliabilityPolicy,
    "parameter_types": Parameter.Type.DOUBLE.name,
    "severity": int(LoggingSeverity.WARN),
    "duration_ns": Duration(seconds=1.5).nanoseconds,
    "time_ns": (Time(seconds=2) + Duration(seconds=1)).nanoseconds,
    "clock": Clock(clock_type=ClockType.STEADY_TIME).clock_type.name,
    "executors": [SingleThreadedExecutor.__name__, MultiThreadedExecutor.__name__],
    "future": Future().done(),
    "remove_ros_args": remove_ros_args(["a", "--ros-args", "-p", "x:=1", "--", "b"]),
    "not_declared_is_key_error": issubclass(ParameterNotDeclaredException, KeyError),
    "logger": get_logger("plain").name,
    "ok_before_init": rclpy.ok(),
}))
"""


def test_rclpy_qos_presets_enums_and_common_names_exist(spawn, tmp_path):
    child = _start(spawn, tmp_path, NAMES)
    out, err = child.finish()
    assert child.returncode == 0, err
    names = json.loads(out.strip().splitlines()[-1])

    assert names["node_is_rosl"] is True
    assert names["sensor_data"] == [5, "BEST_EFFORT"]
    assert names["services_default_depth"] == 10
    assert names["parameter_events_depth"] == 1000
    assert names["system_default_history"] == "SYSTEM_DEFAULT"
    assert names["preset"] == "BEST_EFFORT"
    assert {"RELIABLE", "BEST_EFFORT", "SYSTEM_DEFAULT"} <= set(names["reliability"])
    assert {"VOLATILE", "TRANSIENT_LOCAL"} <= set(names["durability"])
    assert {"KEEP_LAST", "KEEP_ALL"} <= set(names["history"])
    assert names["old_names"] is True
    assert names["parameter_types"] == "DOUBLE"
    assert names["severity"] == 30
    assert names["duration_ns"] == 1_500_000_000
    assert names["time_ns"] == 3_000_000_000
    assert names["clock"] == "STEADY_TIME"
    assert names["executors"] == ["SingleThreadedExecutor", "MultiThreadedExecutor"]
    assert names["future"] is False
    assert names["remove_ros_args"] == ["a", "b"]
    assert names["not_declared_is_key_error"] is True
    assert names["logger"] == "plain"
    assert names["ok_before_init"] is False


EXECUTOR_SCRIPT = """
import rclpy
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Int32


def main():
    rclpy.init()
    node = Node("counter")
    pub = node.create_publisher(Int32, "count", 10)
    state = {"n": 0}

    def tick():
        state["n"] += 1
        pub.publish(Int32(data=state["n"]))

    node.create_timer(0.05, tick)
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    print("spinning", flush=True)
    try:
        executor.spin()
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
    print("done", flush=True)


main()
"""


def test_an_rclpy_script_with_its_own_executor_publishes_and_stops_on_ctrl_c(ros, spawn, tmp_path):
    from std_msgs.msg import Int32

    child = _start(spawn, tmp_path, EXECUTOR_SCRIPT)
    child.expect("^spinning$")
    node = ros.Node("count_listener")
    got: list[int] = []
    node.create_subscription(Int32, "count", lambda m: got.append(m.data), 10)
    assert spin_until(node, lambda: len(got) >= 3, 20.0)
    assert got == sorted(got)

    child.popen.send_signal(signal.SIGINT)
    out, err = child.finish()
    assert child.returncode == 0, err
    assert "Traceback" not in err
    assert out.rstrip().endswith("done")


def test_rosl_spin_and_friends_stay_functions_after_nodes_are_created(ros):
    node = ros.Node("api_check")
    rclpy_spin = __import__("rosl.compat.rclpy", fromlist=["spin"]).spin
    for name in ("init", "ok", "spin", "spin_once", "spin_until_future_complete", "shutdown"):
        assert callable(getattr(ros, name)), f"rosl.{name} is {getattr(ros, name)!r}"
    assert rclpy_spin is ros.spin
    assert node.get_name() == "api_check"


LOOP_SCRIPT = """
import rclpy
from rclpy.node import Node

rclpy.init()
node = Node("looper")
print("looping", flush=True)
try:
    while True:  # no rclpy.ok(): only Ctrl-C ends it, as in rclpy
        rclpy.spin_once(node, timeout_sec=0.1)
except KeyboardInterrupt:
    print("interrupted", flush=True)
node.destroy_node()
rclpy.try_shutdown()
"""


def test_a_script_looping_over_spin_once_without_ok_ends_on_the_first_ctrl_c(spawn, tmp_path):
    child = _start(spawn, tmp_path, LOOP_SCRIPT)
    child.expect("^looping$")
    child.popen.send_signal(signal.SIGINT)
    out, err = child.finish()
    assert not child.stopped_by_us, "one Ctrl-C did not end the loop (it needed a second)"
    assert "interrupted" in out, err
    assert child.returncode == 0, err


WAIT_SCRIPT = """
import rclpy
from rclpy.node import Node
from rclpy.task import Future

rclpy.init()
node = Node("waiter")
never = Future()
print("waiting", flush=True)
try:
    rclpy.spin_until_future_complete(node, never)
    print("returned", never.result(), flush=True)
except KeyboardInterrupt:
    print("interrupted", flush=True)
node.destroy_node()
rclpy.try_shutdown()
"""


def test_ctrl_c_while_spinning_until_a_future_completes_raises_keyboard_interrupt(spawn, tmp_path):
    child = _start(spawn, tmp_path, WAIT_SCRIPT)
    child.expect("^waiting$")
    child.popen.send_signal(signal.SIGINT)
    out, err = child.finish()
    assert not child.stopped_by_us, "one Ctrl-C did not end the wait (it needed a second)"
    assert "interrupted" in out, out + err
    assert "returned" not in out, out + err
    assert child.returncode == 0, err


def test_with_rclpy_init_shuts_down_when_the_block_ends(domain_id):
    import rclpy

    with rclpy.init(args=[]) as guard:
        assert rclpy.ok()
        node = rclpy.create_node("scoped")
        assert node.get_name() == "scoped"
    assert guard.context is rclpy.get_default_context()
    assert not rclpy.ok()
