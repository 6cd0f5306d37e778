"""A subscription of the wrong type: one warning, no callback, no crash; others unaffected."""

from __future__ import annotations

from typing import TYPE_CHECKING

from rosl.graph.records import SUBSCRIPTION
from tests.conftest import wait_until

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

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
assert graph.wait_for(lambda: node.count_publishers("/mixed") >= 1, 30)
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
    assert pub.wait_for_subscribers(2, 30.0) == 2

    def heard_enough() -> bool:
        pub.publish(String(data="hello"))
        return len(listener.matching(r"^heard hello$")) >= 5

    assert wait_until(heard_enough, timeout=30.0, interval=0.05), listener.text("err")

    graph = speaker.participant.graph

    def mismatched() -> int:
        return sum(
            e.stats.get("mismatched", 0)
            for _, e in graph.endpoints(SUBSCRIPTION, "/mixed")
            if e.type == "std_msgs/msg/Int32"
        )

    assert wait_until(lambda: mismatched() >= 5, timeout=15.0)  # counted, not decoded

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


DEFINITION_TALKER = """
import sys
import rosl
from defs_pkg.msg import Reading

rosl.init([])
node = rosl.Node(sys.argv[1])
pub = node.create_publisher(Reading, "/reading", 10)
node.create_timer(0.05, lambda: pub.publish(Reading(value=7)))
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""

DEFINITION_LISTENER = """
import rosl
from defs_pkg.msg import Reading

rosl.init([])
node = rosl.Node("reading_listener")
node.create_subscription(Reading, "/reading", lambda msg: print("heard", msg.value, flush=True), 10)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


def test_a_publisher_with_another_definition_of_the_same_type_is_never_decoded(
    watch: Callable[..., Watched], tmp_path: Path
) -> None:
    def package(folder: str, field: str) -> dict[str, str]:
        root = tmp_path / folder / "defs_pkg"
        (root / "msg").mkdir(parents=True)
        (root / "package.xml").write_text(
            '<?xml version="1.0"?>\n<package format="3"><name>defs_pkg</name>'
            "<version>0.0.0</version></package>\n"
        )
        (root / "msg" / "Reading.msg").write_text(f"{field} value\n")
        return {"ROSL_PACKAGE_PATH": str(tmp_path / folder)}

    edited, current = package("edited", "int64"), package("current", "float64")
    listener = watch(DEFINITION_LISTENER, env=current)
    stale = watch(DEFINITION_TALKER, "stale_talker", env=edited)
    fresh = watch(DEFINITION_TALKER, "fresh_talker", env=current)
    for process in (listener, stale, fresh):
        process.wait_ready()

    # the talker that agrees is heard (7.0 as a float64) ...
    assert wait_until(lambda: len(listener.matching(r"^heard 7\.0$")) >= 5, timeout=30.0), (
        listener.text("err")
    )
    assert wait_until(
        lambda: any("another definition" in line for line in listener.lines("err")), timeout=15.0
    )
    for process in (stale, fresh):
        assert process.interrupt() == 0
    assert listener.interrupt() == 0
    # ... the other one (int64 bytes) never is, and it is named once
    assert set(listener.lines("out")) == {"ready", "heard 7.0"}
    warnings = [line for line in listener.lines("err") if "another definition" in line]
    assert len(warnings) == 1, listener.text("err")
    assert "/stale_talker" in warnings[0]
    assert "defs_pkg/msg/Reading" in warnings[0]
