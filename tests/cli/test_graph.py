"""``rosl graph`` against real nodes: everything shown and marked, filters, formats, files."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import pytest

from tests.cli.conftest import Result, assert_user_error
from tests.graph.support import Watched

if TYPE_CHECKING:
    from collections.abc import Callable
    from pathlib import Path

    from tests.conftest import Processes

SYSTEM = """
import rosl
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan
from std_msgs.msg import String

rosl.init([])
names = ["velocity_controller", "lidar", "scan_reader", "talker", "listener", "_hidden_helper"]
controller, lidar, reader, talker, listener, hidden = nodes = [rosl.Node(n) for n in names]
controller.create_publisher(Twist, "/cmd_vel", 10)
lidar.create_publisher(LaserScan, "/scan", 10)
reader.create_subscription(LaserScan, "/scan", lambda m: None, 10)
talker.create_publisher(String, "/chatter", 10)
listener.create_subscription(String, "/chatter", lambda m: None, 10)
hidden.create_publisher(String, "/_private", 10)
executor = rosl.get_global_executor()
for node in nodes:
    executor.add_node(node)
print("ready", flush=True)
executor.spin()
rosl.shutdown()
"""

ONE_NODE = """
import sys
import rosl

rosl.init([])
node = rosl.Node(sys.argv[1])
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


def run(processes: Processes, *args: str, timeout: float = 30.0) -> Result:
    child = processes.rosl(*args, env={"NO_COLOR": "1"})
    out, err = child.communicate(timeout=timeout)
    return Result(child.returncode, out, err)


@pytest.fixture
def system(processes: Processes) -> Watched:
    child = Watched(processes.python(SYSTEM))
    child.wait_ready()
    return child


def dot_of(processes: Processes, *args: str) -> str:
    result = run(processes, "graph", *args)
    assert result.code == 0, result.err
    assert result.err == ""
    return result.out


def topic_labels(dot: str) -> dict[str, str]:
    return dict(re.findall(r'^  "t:([^"]+)" \[label="([^"]*)"', dot, re.MULTILINE))


def test_dot_draws_every_node_topic_and_edge_of_the_system(system, processes) -> None:
    dot = dot_of(processes)
    assert dot.startswith("digraph rosgraph {\n")
    assert dot.endswith("}\n")
    for node in ("/velocity_controller", "/lidar", "/scan_reader", "/talker", "/listener"):
        assert f'"n:{node}" [label="{node}", shape=ellipse];' in dot
    assert set(topic_labels(dot)) == {"/cmd_vel", "/scan", "/chatter", "/rosout",
                                      "/parameter_events"}  # fmt: skip
    for edge in ('"n:/velocity_controller" -> "t:/cmd_vel";', '"n:/lidar" -> "t:/scan";',
                 '"t:/scan" -> "n:/scan_reader";', '"n:/talker" -> "t:/chatter";',
                 '"t:/chatter" -> "n:/listener";'):  # fmt: skip
        assert f"  {edge}" in dot.splitlines()
    assert '"t:/cmd_vel" ->' not in dot  # nobody reads /cmd_vel
    assert "_hidden_helper" not in dot
    assert "/_private" not in dot
    assert "_rosl_cli_" not in dot


def test_dead_sinks_and_leaf_topics_are_shown_and_marked_in_their_labels(system, processes) -> None:
    labels = topic_labels(dot_of(processes))
    assert labels["/cmd_vel"] == "/cmd_vel\\n[dead sink, leaf]"
    assert labels["/rosout"] == "/rosout\\n[dead sink]"
    assert labels["/scan"] == "/scan"  # one publisher, one subscriber
    assert labels["/chatter"] == "/chatter"


def test_each_hide_filter_removes_what_it_names_and_nothing_else(system, processes) -> None:
    everything = topic_labels(dot_of(processes))
    no_sinks = topic_labels(dot_of(processes, "--hide-dead-sinks"))
    assert set(everything) - set(no_sinks) == {"/cmd_vel", "/rosout", "/parameter_events"}
    no_leaves = topic_labels(dot_of(processes, "--hide-leaf-topics"))
    assert set(everything) - set(no_leaves) == {"/cmd_vel"}
    quiet = dot_of(processes, "--hide-debug", "--hide-params")
    assert set(everything) - set(topic_labels(quiet)) == {"/rosout", "/parameter_events"}
    assert quiet.count("shape=ellipse") == 5
    chosen = dot_of(processes, "--include", "^/scan$", "--exclude", "reader")
    assert set(topic_labels(chosen)) == {"/scan"}
    assert re.findall(r'"n:([^"]+)" \[', chosen) == ["/lidar"]


def test_hidden_nodes_appear_on_request_but_never_the_cli_itself(system, processes) -> None:
    dot = dot_of(processes, "--include-hidden")
    assert '"n:/_hidden_helper"' in dot
    assert '"t:/_private" [label="/_private\\n[dead sink, leaf, hidden]"' in dot
    assert "_rosl_cli_" not in dot


def test_nodes_only_draws_node_to_node_edges_labelled_with_topics(system, processes) -> None:
    dot = dot_of(processes, "--nodes-only", "--hide-debug", "--hide-params")
    assert '  "n:/talker" -> "n:/listener" [label="/chatter"];' in dot.splitlines()
    assert '  "n:/lidar" -> "n:/scan_reader" [label="/scan"];' in dot.splitlines()
    assert (
        '"n:/velocity_controller" [label="/velocity_controller\\n-> /cmd_vel [dead sink, leaf]"'
        in dot
    )
    assert '"t:' not in dot


def test_mermaid_and_text_show_the_same_connections(system, processes) -> None:
    mermaid = run(processes, "graph", "--mermaid", "--hide-params", "--hide-debug")
    assert mermaid.code == 0, mermaid.err
    lines = mermaid.out.splitlines()
    assert lines[0] == "flowchart LR"
    ids = {
        label: ident for ident, label in re.findall(r'^  (\w+)\(?\[\(?"([^"<]+)', mermaid.out, re.M)
    }
    assert f"  {ids['/talker']} --> {ids['/chatter']}" in lines
    assert f"  {ids['/chatter']} --> {ids['/listener']}" in lines
    assert f'  {ids["/cmd_vel"]}["/cmd_vel<br/>[dead sink, leaf]"]' in lines
    text = run(processes, "graph", "--text", "--hide-params", "--hide-debug")
    assert text.code == 0, text.err
    assert (
        "/scan_reader\n  subscribes:\n    /scan [sensor_msgs/msg/LaserScan] <- /lidar\n" in text.out
    )
    assert "    /cmd_vel [geometry_msgs/msg/Twist] -> nobody [dead sink, leaf]" in text.out


def test_text_with_include_says_how_many_readers_were_filtered_out_not_nobody(
    system, processes
) -> None:
    text = run(processes, "graph", "--text", "--include", "talker", "--hide-params", "--hide-debug")
    assert text.code == 0, text.err
    assert text.out == (
        "/talker\n  publishes:\n    /chatter [std_msgs/msg/String] -> 1 filtered out\n"
    )
    both = run(processes, "graph", "--text", "--include", "^/(talker|listener)$", "--hide-debug")
    assert "    /chatter [std_msgs/msg/String] -> /listener\n" in both.out
    reader = run(processes, "graph", "--text", "--include", "scan_reader", "--hide-debug")
    assert "    /scan [sensor_msgs/msg/LaserScan] <- 1 filtered out\n" in reader.out
    nodes_only = dot_of(
        processes, "--nodes-only", "--include", "talker", "--hide-debug", "--hide-params"
    )
    assert '"n:/talker" [label="/talker\\n-> /chatter (1 filtered out)", shape' in nodes_only


def test_output_dot_file_is_written_and_stdout_stays_empty(
    system, processes, tmp_path: Path
) -> None:
    target = tmp_path / "graph.dot"
    result = run(processes, "graph", "-o", str(target))
    assert result.code == 0, result.err
    assert result.out == ""
    written = target.read_text()
    assert written.startswith("digraph rosgraph {")
    assert '"t:/chatter" -> "n:/listener";' in written


def test_png_without_graphviz_is_one_line_exit_1_and_no_file(
    rosl: Callable[..., Result], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))  # no 'dot' anywhere
    target = tmp_path / "graph.png"
    line = assert_user_error(rosl("graph", "-o", str(target)), "graphviz's 'dot' is not installed")
    assert "apt install graphviz" in line
    assert "FILE.dot" in line
    assert not target.exists()


def test_watch_prints_a_new_snapshot_when_a_node_joins(processes: Processes) -> None:
    first = Watched(processes.python(ONE_NODE, "first_node"))
    first.wait_ready()
    watcher = Watched(processes.rosl("graph", "--watch", "--text", env={"NO_COLOR": "1"}))
    assert watcher.wait_for(r"^/first_node$", timeout=30), watcher.text("err")
    Watched(processes.python(ONE_NODE, "second_node")).wait_ready()
    assert watcher.wait_for(r"^/second_node$", timeout=30), watcher.text()
    assert watcher.interrupt() in (0, 130)
    out = watcher.lines()
    assert "---" in out
    assert out.index("---") < out.index("/second_node")
    assert "/second_node" not in out[: out.index("---")]
