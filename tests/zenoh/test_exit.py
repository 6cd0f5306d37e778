"""A program on the Zenoh transport ends without shutting rosl down, as on the others.

zenoh-python's callback threads wait for what they serve to be undeclared; the transport
closes its session before the interpreter waits for threads (a script that never calls
``rclpy.shutdown()`` hung at its end, deaf to SIGTERM).
"""

from __future__ import annotations

import subprocess
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from tests.conftest import Processes
    from tests.zenoh.conftest import Router

NO_SHUTDOWN = """
import rosl
from std_msgs.msg import String

rosl.init()
node = rosl.Node("no_shutdown")
node.create_publisher(String, "/left_open", 10).publish(String(data="x"))
node.create_subscription(String, "/left_open", lambda msg: None, 10)
print("ending", flush=True)
"""


def test_a_program_that_never_shuts_down_ends(processes: Processes, router: Router) -> None:
    child = processes.python(NO_SHUTDOWN)
    try:
        out, err = child.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        child.kill()
        out, err = child.communicate(timeout=10)
        raise AssertionError(f"still running a minute later: {out}{err}") from None

    assert child.returncode == 0, err
    assert out == "ending\n", err
