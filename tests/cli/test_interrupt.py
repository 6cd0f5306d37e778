"""Every command that repeats until Ctrl-C stops on the first SIGINT, quickly and quietly.

Each command runs as a real process against a helper node that publishes, broadcasts TF and
serves (and calls) a service; once the command shows it is in its loop, it gets one SIGINT
(by pid, as ``kill -INT`` sends it) and must exit by itself within a generous bound, with
exit status 130 (an interrupted command is not a success) and no traceback. The same holds
when the command was started as a shell starts a background job, with SIGINT ignored.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
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
    "service call waiting": (["service", "call", "/nobody_serves", "std_srvs/srv/Trigger",
                              "--timeout", "120"], r"^waiting for service to become available"),
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
    # every one is in rosl's own loop by now: a clean stop (rosl's context) or a
    # KeyboardInterrupt caught at rosl's entry, both 130; nothing is left to CPython
    assert code == 130, (code, err)
    assert "Traceback" not in err, err


BACKGROUND = {  # commands with no rosl context of their own: SIGINT is Python's default
    "topic hz": COMMANDS["topic hz"],
    "topic bw": COMMANDS["topic bw"],
    "graph --watch": COMMANDS["graph --watch"],
    "multicast receive": (["multicast", "receive", "--port", "{port}", "--timeout", "120"],
                          r"^Waiting for UDP multicast datagram"),
}  # fmt: skip


def start_as_background_job(processes: Processes, *args: str) -> Watched:
    """``rosl ARGS... &``: a shell starts a background job with SIGINT ignored."""

    def ignore_sigint() -> None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    child = subprocess.Popen(
        [sys.executable, "-m", "rosl", *args],
        env={**os.environ, "PYTHONUNBUFFERED": "1", "NO_COLOR": "1"}, stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        preexec_fn=ignore_sigint,
    )  # fmt: skip
    processes.started.append(child)  # ended by pid by the processes fixture
    return Watched(child)


@pytest.mark.usefixtures("busy_node")
@pytest.mark.parametrize("name", list(BACKGROUND))
def test_a_background_command_ends_on_the_first_sigint(
    processes: Processes, domain_id: int, name: str
) -> None:
    args, running = BACKGROUND[name]
    port = str(40000 + domain_id)  # the test's locked domain picks a port no other test uses
    command = start_as_background_job(processes, *(arg.format(port=port) for arg in args))
    assert command.wait_for(running, timeout=30.0), (
        f"never got going\n{command.text()}\n{command.text('err')}"
    )
    command.send(signal.SIGINT)  # once, as `kill -INT %1` does
    try:
        code = command.child.wait(timeout=EXIT_BOUND_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f"rosl {name} & still running {EXIT_BOUND_S} s after one SIGINT")
    command.interrupt(timeout=5.0)  # joins the output readers
    err = command.text("err")
    assert code == 130, (code, err)
    assert "Traceback" not in err, err
