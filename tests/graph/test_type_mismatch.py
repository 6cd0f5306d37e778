"""A subscription of the wrong type: one warning, no callback, no crash; others unaffected."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rosl.graph.records import SUBSCRIPTION
from tests.conftest import wait_until

if TYPE_CHECKING:
    from collections.abc import Callable

    from tests.graph.support import Watched

MIXED_LISTENER = """
import rosl
from std_msgs.msg import Int32, String

rosl.init([])
node = rosl.Node("mixed_listener")
node.create_subscription(Int32, "/mixed", lambda msg: print("WRONG", msg, flush=True), 10)
node.create_subscription(String, "/mixed", lambda msg: print("heard", msg.data, flush=True), 10)
graph = node.participant.graph
# ready once the publisher is known, so the warning can name its type
assert graph.wait_for(lambda: node.count_publishers("/mixed") >= 1, 10)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


def test_a_subscription_of_another_type_warns_once_and_never_calls_back(
    watch: Callable[..., Watched], ros: object
) -> None:
    from std_msgs.msg import String

    speaker = ros.Node("speaker")  # type: ignore[attr-defined]
    pub = speaker.create_publisher(String, "/mixed", 10)
    listener = watch(MIXED_LISTENER)
    listener.wait_ready()
    assert pub.wait_for_subscribers(2, 10.0) == 2

    def heard_enough() -> bool:
        pub.publish(String(data="hello"))
        return len(listener.matching(r"^heard hello$")) >= 5

    assert wait_until(heard_enough, timeout=10.0, interval=0.05), listener.text("err")

    graph = speaker.participant.graph

    def mismatched() -> int:
        return sum(
            e.stats.get("mismatched", 0)
            for _, e in graph.endpoints(SUBSCRIPTION, "/mixed")
            if e.type == "std_msgs/msg/Int32"
        )

    assert wait_until(lambda: mismatched() >= 5, timeout=5.0)  # counted, not decoded

    assert listener.interrupt() == 0
    err = listener.text("err")
    warnings = [line for line in listener.lines("err") if "/mixed" in line and "WARN" in line]
    assert len(warnings) == 1, err
    (warning,) = warnings
    assert "std_msgs/msg/Int32" in warning
    assert "std_msgs/msg/String" in warning
    assert "/speaker" in warning  # who sent it
    assert "WRONG" not in listener.text("out")
    assert "Traceback" not in err
