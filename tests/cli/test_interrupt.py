"""Every command that repeats until Ctrl-C stops on the first SIGINT, quickly and quietly.

Each command runs as a real process against a helper node that publishes, broadcasts TF and
serves (and calls) a service; once the command shows it is in its loop, it gets one SIGINT
(by pid, as ``kill -INT`` sends it) and must exit by itself within a generous bound, with no
traceback.
"""

from __future__ import annotations

import signal
import subprocess
from typing import TYPE_CHECKING

import pytest

from rosl.graph.records import PUBLISHER, SERVER
from tests.graph.support import Watched

if TYPE_CHECKING:
    from tests.conftest import Processes

EXIT_BOUND_S = 20.0  # generous: a clean exit takes well under a second

BUSY_NODE = """
import rosl
from geometry_msgs.msg import PoseStamped, TransformStamped
from std_msgs.msg import String
from std_srvs.srv import Trigger
from tf2_msgs.msg import TFMessage

rosl.init()
node = rosl.Node("busy")
chatter = node.create_publisher(String, "/chatter", 10)
pose = node.create_publisher(PoseStamped, "/pose", 10)
tf = node.create_publisher(TFMessage, "/tf", 10)
node.create_service(Trigger, "/trig", lambda request, response: response)
client = node.create_client(Trigger, "/trig")


def tick():
    stamp = node.get_clock().now().to_msg()
    chatter.publish(String(data="hi"))
    message = PoseStamped()
    message.header.stamp = stamp
    pose.publish(message)
    transform = TransformStamped()
    transform.header.stamp = stamp
    transform.header.frame_id = "a"
    transform.child_frame_id = "b"
    transform.transform.rotation.w = 1.0
    tf.publish(TFMessage(transforms=[transform]))


node.create_timer(0.05, tick)
node.create_timer(0.2, lambda: client.call_async(Trigger.Request()))
rosl.spin(node)
"""

COMMANDS = {  # the command, and the output line that shows it is in its loop
    "service call -r": (["service", "call", "-r", "1", "/trig", "std_srvs/srv/Trigger"],
                        r"^response:"),
    "topic pub -r": (["topic", "pub", "-r", "5", "/x", "std_msgs/msg/String", "{data: a}"],
                     r"^publishing #1"),
    "topic pub": (["topic", "pub", "/x", "std_msgs/msg/String", "{data: a}"], r"^publishing #1"),
    "topic pub -1 waiting": (["topic", "pub", "-1", "/nobody_listens", "std_msgs/msg/String",
                              "{data: a}", "--max-wait-time-secs", "120"],
                             r"^Waiting for at least 1 matching"),
    "topic echo": (["topic", "echo", "/chatter"], r"^data: hi"),
    "topic hz": (["topic", "hz", "/chatter"], r"^average rate"),
    "topic bw": (["topic", "bw", "/chatter"], r"B/s from"),
    "topic delay": (["topic", "delay", "/pose"], r"^average delay"),
    "service echo": (["service", "echo", "/trig"], r"event_type: REQUEST_SENT"),
    "tf echo": (["tf", "echo", "a", "b"], r"Translation"),
    "graph --watch": (["graph", "--watch"], r"digraph"),
}  # fmt: skip


@pytest.fixture
def busy_node(processes: Processes) -> None:
    """The helper node, up with its publishers and its service."""
    from rosl.introspection.session import Session

    busy = Watched(processes.python(BUSY_NODE))
    with Session() as session:
        graph = session.graph()
        up = graph.wait_for(
            lambda: (
                graph.count(SERVER, "/trig") == 1
                and all(graph.count(PUBLISHER, t) == 1 for t in ("/chatter", "/pose", "/tf"))
            ),
            30.0,
        )
    assert up, f"the helper node is not up (exit {busy.child.poll()})\n{busy.text('err')}"


@pytest.mark.usefixtures("busy_node")
@pytest.mark.parametrize("name", list(COMMANDS))
def test_a_repeating_command_ends_on_the_first_sigint(processes: Processes, name: str) -> None:
    args, running = COMMANDS[name]
    command = Watched(processes.rosl(*args, env={"NO_COLOR": "1"}))
    assert command.wait_for(running, timeout=30.0), (
        f"never got going\n{command.text()}\n{command.text('err')}"
    )
    command.send(signal.SIGINT)  # once
    try:
        code = command.child.wait(timeout=EXIT_BOUND_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"rosl {name} still running {EXIT_BOUND_S} s after one SIGINT")
    command.interrupt(timeout=5.0)  # joins the output readers
    err = command.text("err")
    # 0: a clean shutdown; 130: KeyboardInterrupt caught; -2: Python's own exit for one that
    # crossed an exec() of a string (a class being built) on its way out
    assert code in (0, 130, -signal.SIGINT), (code, err)
    assert "Traceback" not in err, err
