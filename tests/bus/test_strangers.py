"""A process under another key (standing for another user on this host) is not heard.

It cannot publish to our subscriptions, call our services, set our parameters, or appear in
our graph; and our nodes are not in its graph. The same stranger under our key does all of
it, so the test would notice a key that protected nothing.
"""

from __future__ import annotations

import subprocess
import sys
from typing import TYPE_CHECKING

import pytest

from tests.bus.helpers import Lines

if TYPE_CHECKING:
    from tests.conftest import Processes

TARGET = r"""
import rosl.compat

rosl.compat.install()  # rclpy is rosl's (what `rosl run` does for a script)
import rclpy
from rclpy.node import Node
from rcl_interfaces.msg import SetParametersResult
from std_msgs.msg import String
from example_interfaces.srv import AddTwoInts

rclpy.init()
node = Node("guarded")
node.declare_parameter("timer_period_s", 1.0)
node.create_subscription(String, "/guarded_in", lambda m: print("heard", m.data, flush=True), 10)


def add(request, response):
    print("called", request.a, request.b, flush=True)
    response.sum = request.a + request.b
    return response


def on_parameters(parameters):
    for parameter in parameters:
        print("parameter", parameter.name, parameter.value, flush=True)
    return SetParametersResult(successful=True)


node.create_service(AddTwoInts, "/guarded_add", add)
node.add_on_set_parameters_callback(on_parameters)
print("up", flush=True)
try:
    rclpy.spin(node)
except KeyboardInterrupt:
    pass
"""

# Sends blindly (it does not wait for discovery, which would not show it the target): a
# publication, a service request and a parameter change, 20 times each; then stays in the
# graph until its stdin closes.
STRANGER = r"""
import sys
import rosl.compat

rosl.compat.install()
import rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from rcl_interfaces.srv import SetParameters
from std_msgs.msg import String
from example_interfaces.srv import AddTwoInts

rclpy.init()
node = Node("stranger")
publisher = node.create_publisher(String, "/guarded_in", 10)
client = node.create_client(AddTwoInts, "/guarded_add")
setter = node.create_client(SetParameters, "/guarded/set_parameters")
change = Parameter("timer_period_s", Parameter.Type.DOUBLE, 0.25).to_parameter_msg()
for _ in range(20):
    publisher.publish(String(data="evil"))
    client.call_async(AddTwoInts.Request(a=1, b=2))
    setter.call_async(SetParameters.Request(parameters=[change]))
    rclpy.spin_once(node, timeout_sec=0.05)
print("sent", flush=True)
sys.stdin.read()
"""


def run(processes: Processes, args: list[str], env: dict[str, str]) -> tuple[int, str, str]:
    child = processes.rosl(*args, env=env)
    try:
        out, err = child.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        child.kill()
        out, err = child.communicate(timeout=5)
    return child.returncode, out, err


def start_stranger(processes: Processes, env: dict[str, str]) -> subprocess.Popen[str]:
    return processes.start([sys.executable, "-c", STRANGER], env=env, stdin=subprocess.PIPE)


def end(child: subprocess.Popen[str]) -> None:
    assert child.stdin is not None
    child.stdin.close()
    child.wait(15)


@pytest.mark.slow
def test_another_key_can_neither_publish_call_set_nor_be_seen(processes: Processes) -> None:
    ours = {"ROSL_KEY": "our team"}
    theirs = {"ROSL_KEY": "another user"}
    target = processes.start([sys.executable, "-c", TARGET], env=ours)
    heard = Lines(target.stdout)
    assert heard.wait_line("up", 30.0), "the target node did not start"

    stranger = start_stranger(processes, theirs)
    assert Lines(stranger.stdout).wait_line("sent", 60.0), "the stranger did not run"
    code, out, err = run(processes, ["node", "list"], ours)
    assert code == 0, err
    assert "/guarded" in out.split()
    assert "/stranger" not in out.split()  # not in our graph
    code, out, err = run(processes, ["node", "list"], theirs)
    assert code == 0, err
    assert "/stranger" in out.split()  # it sees itself ...
    assert "/guarded" not in out.split()  # ... and not us
    code, out, err = run(processes, ["param", "set", "/guarded", "timer_period_s", "0.25"], theirs)
    assert code != 0
    assert "Node not found" in out + err
    end(stranger)
    # a message under our key, sent after all of the stranger's: when the target has it, it
    # has read past everything the stranger sent
    code, _, err = run(
        processes, ["topic", "pub", "--once", "/guarded_in", "std_msgs/msg/String",
                    "{data: marker}"], ours,
    )  # fmt: skip
    assert code == 0, err
    assert heard.wait_line("heard marker", 30.0), heard.lines
    assert [line for line in heard.lines if line not in ("up", "heard marker")] == []
    code, out, _ = run(processes, ["param", "get", "/guarded", "timer_period_s"], ours)
    assert "1.0" in out

    # the control: the same stranger under our key is heard, served and obeyed
    friend = start_stranger(processes, ours)
    assert heard.wait_for(
        lambda lines: {"heard", "called", "parameter"} <= {x.split()[0] for x in lines}, 60.0
    ), f"a process under the same key was not heard: {heard.lines}"
    end(friend)
