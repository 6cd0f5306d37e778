"""``rosl node list|info`` against real nodes in other processes, compared with ROS 2's texts."""

from __future__ import annotations

import pytest

from tests.cli.conftest import Result, assert_user_error, run
from tests.graph.support import Watched

NODES = """
import sys
import rosl

rosl.init([])
nodes = []
for full in sys.argv[1:]:
    namespace, _, name = full.rpartition("/")
    nodes.append(rosl.Node(name, namespace=namespace or "/"))
executor = rosl.get_global_executor()
for node in nodes:
    executor.add_node(node)
print("ready", flush=True)
executor.spin()
rosl.shutdown()
"""  # argv: node names, "/ns/name" for a namespace

COMPLEX_NODE = """
import rosl
from std_msgs.msg import Int32, String
from std_srvs.srv import SetBool, Trigger

rosl.init([])
node = rosl.Node("complex_node")
node.create_publisher(String, "/chatter", 10)
node.create_publisher(String, "/_private", 10)
node.create_publisher(String, "~/status", 10)
node.create_subscription(Int32, "/numbers", lambda msg: None, 10)
node.create_service(Trigger, "/reset", lambda request, response: response)
node.create_client(SetBool, "/enable")
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""

PARAMETER_SERVICES = [
    "    /complex_node/describe_parameters: rcl_interfaces/srv/DescribeParameters",
    "    /complex_node/get_parameter_types: rcl_interfaces/srv/GetParameterTypes",
    "    /complex_node/get_parameters: rcl_interfaces/srv/GetParameters",
    "    /complex_node/list_parameters: rcl_interfaces/srv/ListParameters",
    "    /complex_node/set_parameters: rcl_interfaces/srv/SetParameters",
    "    /complex_node/set_parameters_atomically: rcl_interfaces/srv/SetParametersAtomically",
]
INFO = [
    "/complex_node",
    "  Subscribers:",
    "    /numbers: std_msgs/msg/Int32",
    "  Publishers:",
    "    /chatter: std_msgs/msg/String",
    "    /complex_node/status: std_msgs/msg/String",
    "    /parameter_events: rcl_interfaces/msg/ParameterEvent",
    "    /rosout: rcl_interfaces/msg/Log",
    "  Service Servers:",
    *PARAMETER_SERVICES,
    "    /reset: std_srvs/srv/Trigger",
    "  Service Clients:",
    "    /enable: std_srvs/srv/SetBool",
    "  Action Servers:",
    "",  # ros2 prints an empty line for a section with nothing in it
    "  Action Clients:",
    "",
]
DUPLICATE_WARNING = (
    "WARNING: Be aware that there are nodes in the graph that share an exact name, which can "
    "have unintended side effects.\n"
)


@pytest.fixture
def start(processes):
    """Start a program printing ``ready`` once its nodes are up."""

    def run(code: str, *args: str) -> Watched:
        child = Watched(processes.python(code, *args))
        child.wait_ready()
        return child

    return run


def node(processes, *args: str) -> Result:
    return run(processes, "node", *args)


def test_node_list_prints_full_names_sorted_and_hidden_ones_only_with_all(start, processes) -> None:
    start(NODES, "zeta", "alpha", "/ns/beta", "_hidden")
    assert node(processes, "list") == Result(0, "/alpha\n/ns/beta\n/zeta\n", "")
    assert node(processes, "list", "-a") == Result(0, "/_hidden\n/alpha\n/ns/beta\n/zeta\n", "")
    assert node(processes, "list", "--all") == node(processes, "list", "-a")


def test_node_list_count_prints_only_the_number(start, processes) -> None:
    start(NODES, "zeta", "alpha", "/ns/beta", "_hidden")
    assert node(processes, "list", "-c") == Result(0, "3\n", "")
    assert node(processes, "list", "--count-nodes") == Result(0, "3\n", "")
    assert node(processes, "list", "-a", "-c") == Result(0, "4\n", "")


def test_node_list_with_no_nodes_prints_nothing(processes) -> None:
    assert node(processes, "list") == Result(0, "", "")
    assert node(processes, "list", "-c") == Result(0, "0\n", "")


def test_node_list_warns_on_stderr_about_nodes_sharing_a_name(start, processes) -> None:
    start(NODES, "twin", "solo")
    start(NODES, "twin")
    assert node(processes, "list") == Result(0, "/solo\n/twin\n/twin\n", DUPLICATE_WARNING)
    assert node(processes, "list", "-c") == Result(0, "3\n", "")


def test_node_info_prints_ros2s_six_sections(start, processes) -> None:
    start(COMPLEX_NODE)
    result = node(processes, "info", "/complex_node")
    assert (result.code, result.err) == (0, "")
    assert result.out == "\n".join(INFO) + "\n"


def test_node_info_include_hidden_adds_hidden_topics(start, processes) -> None:
    start(COMPLEX_NODE)
    result = node(processes, "info", "/complex_node", "--include-hidden")
    assert (result.code, result.err) == (0, "")
    lines = result.out.splitlines()
    publishers = lines[lines.index("  Publishers:") + 1 : lines.index("  Service Servers:")]
    assert publishers == [
        "    /_private: std_msgs/msg/String",
        "    /chatter: std_msgs/msg/String",
        "    /complex_node/status: std_msgs/msg/String",
        "    /parameter_events: rcl_interfaces/msg/ParameterEvent",
        "    /rosout: rcl_interfaces/msg/Log",
    ]


def test_node_info_of_an_unknown_node_names_the_closest_one(start, processes) -> None:
    start(COMPLEX_NODE)
    line = assert_user_error(node(processes, "info", "/complex_nod"))
    assert line == "Unable to find node '/complex_nod' (did you mean '/complex_node'?)"
    assert assert_user_error(node(processes, "info", "/nothing_like_it")) == (
        "Unable to find node '/nothing_like_it'"
    )


def test_node_info_of_a_shared_name_warns_and_shows_one(start, processes) -> None:
    start(NODES, "twin")
    start(NODES, "twin")
    result = node(processes, "info", "/twin")
    assert result.code == 0
    assert result.err == (
        'There are 2 nodes in the graph with the exact name "/twin". '
        "You are seeing information about only one of them.\n"
    )
    assert result.out.splitlines()[:3] == ["/twin", "  Subscribers:", ""]


def test_node_info_of_the_tutorial_publisher_started_with_rosl_run(processes) -> None:
    publisher = Watched(processes.rosl("run", "tutorial_pkg", "my_publisher"))
    assert publisher.wait_for(r"Publishing: counter=1 ", "err", timeout=30.0), publisher.text("err")
    result = node(processes, "info", "/my_publisher")
    assert (result.code, result.err) == (0, "")
    lines = result.out.splitlines()
    assert lines[:3] == ["/my_publisher", "  Subscribers:", ""]
    assert "    /my_data: tutorial_pkg/msg/MyData" in lines
    assert lines[-4:] == ["  Action Servers:", "", "  Action Clients:", ""]


def test_node_info_of_a_hidden_node_needs_include_hidden_as_ros2(start, processes) -> None:
    start(NODES, "_hidden_complex_node", "complex_node")
    result = node(processes, "info", "/_hidden_complex_node")
    assert result == Result(1, "", "Unable to find node '/_hidden_complex_node'\n")
    shown = node(processes, "info", "/_hidden_complex_node", "--include-hidden")
    assert (shown.code, shown.err) == (0, "")
    assert shown.out.splitlines()[:2] == ["/_hidden_complex_node", "  Subscribers:"]
    # a misspelt name is only compared with the nodes shown
    line = assert_user_error(node(processes, "info", "/_hidden_complex_nod"))
    assert line == "Unable to find node '/_hidden_complex_nod' (did you mean '/complex_node'?)"
