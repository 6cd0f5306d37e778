"""The graph picture's model, filters and renderers, on hand-made graphs (no bus)."""

from __future__ import annotations

import re

import pytest

from rosl.graph.cache import GraphCache
from rosl.graph.records import (
    CLIENT,
    PUBLISHER,
    SERVER,
    SUBSCRIPTION,
    EndpointRecord,
    NodeRecord,
    ProcessRecord,
)
from rosl.introspection import graph_view
from rosl.introspection.errors import IntrospectionError
from rosl.introspection.graph_view import GraphOptions, build

TWIST, SCAN, STRING = "geometry_msgs/msg/Twist", "sensor_msgs/msg/LaserScan", "std_msgs/msg/String"
LOG, EVENTS = "rcl_interfaces/msg/Log", "rcl_interfaces/msg/ParameterEvent"


def make_node(name: str, process: int, *endpoints: tuple[str, str, str]) -> NodeRecord:
    ns, _, base = name.rpartition("/")
    standard = [(PUBLISHER, "/rosout", LOG), (PUBLISHER, "/parameter_events", EVENTS)]
    records = tuple(
        EndpointRecord(kind, topic, type_, i)
        for i, (kind, topic, type_) in enumerate([*endpoints, *standard], 1)
    )
    return NodeRecord(base, ns or "/", process, 1, records)


def graph_of(*nodes: NodeRecord) -> GraphCache:
    cache = GraphCache()
    processes: dict[int, list[NodeRecord]] = {}
    for node in nodes:
        processes.setdefault(node.process, []).append(node)
    for sender, members in processes.items():
        cache.update(ProcessRecord(sender, sender, "host", tuple(members), 1))
    return cache


def seed_system() -> GraphCache:
    """The seed's story: /cmd_vel with no subscriber, /scan read once, a talker/listener pair."""
    return graph_of(
        make_node("/velocity_controller", 1, (PUBLISHER, "/cmd_vel", TWIST)),
        make_node("/lidar", 2, (PUBLISHER, "/scan", SCAN)),
        make_node("/scan_reader", 3, (SUBSCRIPTION, "/scan", SCAN)),
        make_node("/talker", 4, (PUBLISHER, "/chatter", STRING)),
        make_node("/listener", 5, (SUBSCRIPTION, "/chatter", STRING)),
        make_node("/rviz2", 6, (SUBSCRIPTION, "/tf", "tf2_msgs/msg/TFMessage")),
        make_node("/_hidden_helper", 7, (PUBLISHER, "/_private", STRING)),
    )


def topics(model: graph_view.GraphModel) -> dict[str, tuple[str, ...]]:
    return {c.name: c.marks for c in model.topics}


def test_everything_is_shown_by_default_and_loose_topics_are_marked() -> None:
    model = build(seed_system(), GraphOptions())
    assert list(model.nodes) == [
        "/lidar", "/listener", "/rviz2", "/scan_reader", "/talker", "/velocity_controller",
    ]  # fmt: skip
    assert topics(model) == {
        "/chatter": (),
        "/cmd_vel": ("dead sink", "leaf"),
        "/parameter_events": ("dead sink",),
        "/rosout": ("dead sink",),
        "/scan": (),
        "/tf": ("leaf",),
    }
    chatter = next(c for c in model.topics if c.name == "/chatter")
    assert (chatter.sources, chatter.sinks) == (("/talker",), ("/listener",))


def test_hide_dead_sinks_removes_only_topics_without_subscribers() -> None:
    model = build(seed_system(), GraphOptions(hide_dead_sinks=True))
    assert set(topics(model)) == {"/chatter", "/scan", "/tf"}
    assert len(model.nodes) == 6


def test_hide_leaf_topics_removes_only_topics_with_one_connection() -> None:
    model = build(seed_system(), GraphOptions(hide_leaf_topics=True))
    assert set(topics(model)) == {"/chatter", "/scan", "/parameter_events", "/rosout"}
    assert len(model.nodes) == 6


def test_hide_debug_removes_rqt_debug_names_nodes_and_topics() -> None:
    cache = seed_system()
    cache.update(ProcessRecord(8, 8, "h", (make_node("/diag/_internal", 8),), 1))
    model = build(cache, GraphOptions(hide_debug=True, include_hidden=True))
    assert "/rviz2" not in model.nodes
    assert "/diag/_internal" not in model.nodes
    assert "/rosout" not in topics(model)
    assert "/_private" not in topics(model)  # last token starts with _
    assert "/tf" not in topics(model)  # only /rviz2 used it
    assert {"/chatter", "/cmd_vel", "/scan", "/parameter_events"} <= set(topics(model))
    assert "/_hidden_helper" not in model.nodes
    assert "/talker" in model.nodes


def test_hide_params_removes_parameter_topics_and_services_only() -> None:
    cache = graph_of(
        make_node("/server", 1, (SERVER, "/server/get_parameters", "rcl_interfaces/srv/GetParameters"),
                  (SERVER, "/add", "example_interfaces/srv/AddTwoInts")),
        make_node("/client", 2, (CLIENT, "/add", "example_interfaces/srv/AddTwoInts")),
    )  # fmt: skip
    model = build(cache, GraphOptions(hide_params=True, services=True))
    assert [c.name for c in model.channels] == ["/add", "/rosout"]
    plain = build(cache, GraphOptions(services=True))
    assert "/server/get_parameters" in [c.name for c in plain.services]
    assert "/parameter_events" in topics(plain)


def test_include_keeps_matches_and_their_direct_neighbours() -> None:
    model = build(seed_system(), GraphOptions(include=("^/talker$",)))
    assert list(model.nodes) == ["/talker"]
    assert set(topics(model)) == {"/chatter", "/rosout", "/parameter_events"}
    assert next(c for c in model.topics if c.name == "/chatter").sinks == ()
    by_topic = build(seed_system(), GraphOptions(include=("^/scan$",)))
    assert list(by_topic.nodes) == ["/lidar", "/scan_reader"]
    assert set(topics(by_topic)) == {"/scan"}


def test_exclude_drops_matching_names_and_topics_left_without_nodes() -> None:
    model = build(seed_system(), GraphOptions(exclude=("lidar", "^/chatter$")))
    assert "/lidar" not in model.nodes
    assert "/chatter" not in topics(model)
    scan = next(c for c in model.topics if c.name == "/scan")
    assert scan.sources == ()
    assert scan.sinks == ("/scan_reader",)
    assert {"/talker", "/listener", "/scan_reader"} <= set(model.nodes)


def test_a_bad_regular_expression_is_a_one_line_error() -> None:
    with pytest.raises(IntrospectionError, match="bad regular expression"):
        build(seed_system(), GraphOptions(include=("(",)))


def test_hidden_nodes_only_on_request_and_never_this_process() -> None:
    cache = seed_system()
    cache.update(ProcessRecord(99, 99, "h", (make_node("/_rosl_cli_99", 99),), 1))
    assert "/_hidden_helper" not in build(cache, GraphOptions()).nodes
    shown = build(cache, GraphOptions(include_hidden=True), own_process=99)
    assert "/_hidden_helper" in shown.nodes
    assert topics(shown)["/_private"] == ("dead sink", "leaf", "hidden")
    assert "/_rosl_cli_99" not in shown.nodes


def test_duplicates_and_type_mismatches_are_visible_in_labels() -> None:
    cache = graph_of(
        make_node("/twin", 1, (PUBLISHER, "/mixed", STRING)),
        make_node("/twin", 2, (SUBSCRIPTION, "/mixed", "std_msgs/msg/Int32")),
    )
    model = build(cache, GraphOptions())
    assert model.nodes == {"/twin": 2}
    assert topics(model)["/mixed"] == ("2 types",)
    assert "/twin (x2, duplicate name)" in graph_view.to_dot(model)


def test_dot_ids_of_a_node_and_a_topic_with_the_same_name_do_not_collide() -> None:
    cache = graph_of(make_node("/chatter", 1, (PUBLISHER, "/chatter", STRING)))
    dot = graph_view.to_dot(build(cache, GraphOptions()))
    assert '"n:/chatter" [label="/chatter", shape=ellipse];' in dot
    assert '"t:/chatter" [label="/chatter\\n[dead sink, leaf]", shape=box, color="red"];' in dot
    assert '"n:/chatter" -> "t:/chatter";' in dot


STATEMENT = re.compile(r'^  "[nts]:[^"]+"( -> "[nts]:[^"]+")? ?(\[.*\])?;$')


def test_dot_is_valid_and_the_same_whatever_the_discovery_order() -> None:
    forward = graph_view.to_dot(build(seed_system(), GraphOptions(services=True)))
    nodes = [n for p in seed_system().processes() for n in p.nodes]
    backward = graph_view.to_dot(build(graph_of(*reversed(nodes)), GraphOptions(services=True)))
    assert forward == backward
    lines = forward.splitlines()
    assert lines[:3] == ["digraph rosgraph {", "  rankdir=LR;", "  node [fontsize=10];"]
    assert lines[-1] == "}"
    for line in lines[3:-1]:
        assert STATEMENT.match(line), line


def test_services_are_diamonds_from_client_to_server() -> None:
    cache = graph_of(
        make_node("/server", 1, (SERVER, "/add", "example_interfaces/srv/AddTwoInts")),
        make_node("/client", 2, (CLIENT, "/add", "example_interfaces/srv/AddTwoInts"),
                  (CLIENT, "/nobody_serves", "std_srvs/srv/Empty")),
    )  # fmt: skip
    dot = graph_view.to_dot(build(cache, GraphOptions(services=True)))
    assert '"s:/add" [label="/add", shape=diamond];' in dot
    assert '"n:/client" -> "s:/add" [style=dashed];' in dot
    assert '"s:/add" -> "n:/server" [style=dashed];' in dot
    assert '"s:/nobody_serves" [label="/nobody_serves\\n[no server]"' in dot
    assert "s:/add" not in graph_view.to_dot(build(cache, GraphOptions()))


def test_nodes_only_labels_edges_with_topics_and_keeps_dead_sinks_on_the_node() -> None:
    cache = graph_of(
        make_node("/a", 1, (PUBLISHER, "/x", STRING), (PUBLISHER, "/y", STRING)),
        make_node("/b", 2, (SUBSCRIPTION, "/x", STRING), (SUBSCRIPTION, "/y", STRING)),
    )
    dot = graph_view.to_dot(build(cache, GraphOptions(hide_params=True)), nodes_only=True)
    assert '"n:/a" -> "n:/b" [label="/x\\n/y"];' in dot
    assert '"n:/a" [label="/a\\n-> /rosout [dead sink]", shape=ellipse];' in dot
    assert '"t:' not in dot
    mermaid = graph_view.to_mermaid(build(cache, GraphOptions()), nodes_only=True)
    assert '  n1 -->|"/x<br/>/y"| n2' in mermaid.splitlines()


def test_mermaid_and_text_show_the_same_picture() -> None:
    model = build(seed_system(), GraphOptions(hide_params=True, hide_debug=True))
    mermaid = graph_view.to_mermaid(model).splitlines()
    assert mermaid[0] == "flowchart LR"
    assert '  n4(["/talker"])' in mermaid
    assert '  t2["/cmd_vel<br/>[dead sink, leaf]"]' in mermaid
    assert "  n4 --> t1" in mermaid
    assert "  t1 --> n2" in mermaid
    assert "  class t2 loose;" in mermaid
    text = graph_view.to_text(model)
    assert "/talker\n  publishes:\n    /chatter [std_msgs/msg/String] -> /listener\n" in text
    assert "/listener\n  subscribes:\n    /chatter [std_msgs/msg/String] <- /talker\n" in text
    assert "    /cmd_vel [geometry_msgs/msg/Twist] -> nobody [dead sink, leaf]" in text
    assert graph_view.to_text(build(GraphCache(), GraphOptions())) == "(no nodes)\n"


FIB = "example_interfaces/action/Fibonacci"


def action_graph() -> GraphCache:
    """An action server and a client of /fibonacci, with the endpoints ROS 2 makes for it."""
    base = "/fibonacci/_action/"
    server = [
        (SERVER, base + "send_goal", FIB + "_SendGoal"),
        (SERVER, base + "cancel_goal", "action_msgs/srv/CancelGoal"),
        (SERVER, base + "get_result", FIB + "_GetResult"),
        (PUBLISHER, base + "feedback", FIB + "_FeedbackMessage"),
        (PUBLISHER, base + "status", "action_msgs/msg/GoalStatusArray"),
    ]
    client = [
        (CLIENT, base + "send_goal", FIB + "_SendGoal"),
        (SUBSCRIPTION, base + "feedback", FIB + "_FeedbackMessage"),
        (SUBSCRIPTION, base + "status", "action_msgs/msg/GoalStatusArray"),
    ]
    return graph_of(make_node("/fib_server", 1, *server), make_node("/fib_client", 2, *client))


def test_an_action_is_drawn_once_from_its_clients_to_its_servers() -> None:
    model = build(action_graph(), GraphOptions())

    (action,) = model.actions
    assert (action.name, action.types) == ("/fibonacci", (FIB,))
    assert (action.sources, action.sinks, action.marks) == (("/fib_client",), ("/fib_server",), ())
    assert not [c for c in model.channels if "_action" in c.name]  # its topics stay hidden
    dot = graph_view.to_dot(model)
    assert '"a:/fibonacci" [label="/fibonacci", shape=hexagon];' in dot
    assert '"n:/fib_client" -> "a:/fibonacci" [style=bold];' in dot
    assert '"a:/fibonacci" -> "n:/fib_server" [style=bold];' in dot
    text = graph_view.to_text(model)
    assert f"  serves actions:\n    /fibonacci [{FIB}] <- /fib_client\n" in text
    assert f"  sends goals:\n    /fibonacci [{FIB}] -> /fib_server\n" in text
    assert 'a1{{"/fibonacci"}}' in graph_view.to_mermaid(model)


def test_an_action_nobody_serves_is_marked() -> None:
    graph = action_graph()
    graph.remove(1)

    (action,) = build(graph, GraphOptions()).actions

    assert action.marks == ("no server",)
