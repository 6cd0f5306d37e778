"""``rosl lifecycle nodes/list/get/set`` against managed nodes in other processes (ros2lifecycle).

The texts are ros2lifecycle's (``label [id]``, ``- label [id]`` with tab-indented Start/Goal,
'Transitioning successful'); a missing node, a node that is not managed, a transition the node
does not offer and a refused transition are one line on stderr and exit 1.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from rosl.graph.records import SERVER
from tests.cli.conftest import Result, assert_user_error, run, wait_graph

if TYPE_CHECKING:
    from tests.conftest import Processes

NODES = """
import rosl.compat; rosl.compat.install(force=True)
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.lifecycle import Node, TransitionCallbackReturn
from rclpy.node import Node as PlainNode

class Refuser(Node):
    def on_configure(self, state):
        return TransitionCallbackReturn.FAILURE

rclpy.init()
executor = SingleThreadedExecutor()
for node in (Node("lc_talker"), Node("lc_other", namespace="/robot"), Refuser("refuser"),
             PlainNode("plain")):
    executor.add_node(node)
executor.spin()
"""

UNCONFIGURED = """\
- configure [1]
\tStart: unconfigured
\tGoal: configuring
- shutdown [5]
\tStart: unconfigured
\tGoal: shuttingdown
"""


@pytest.fixture
def managed(processes: Processes) -> None:
    """Three lifecycle nodes (one refuses to configure) and a plain one, in another process."""
    processes.python(NODES)
    wait_graph(
        lambda g: (
            g.count(SERVER, "/refuser/get_transition_graph") == 1
            and g.count(SERVER, "/plain/set_parameters") == 1
        )
    )


def test_nodes_lists_the_lifecycle_nodes_only(managed, processes) -> None:
    names = "/lc_talker\n/refuser\n/robot/lc_other\n"
    assert run(processes, "lifecycle", "nodes") == Result(0, names, "")
    assert run(processes, "lifecycle", "nodes", "-c") == Result(0, "3\n", "")


def test_get_set_and_list_walk_a_node_through_its_states(managed, processes) -> None:
    assert run(processes, "lifecycle", "get", "/lc_talker") == Result(0, "unconfigured [1]\n", "")
    assert run(processes, "lifecycle", "list", "lc_talker") == Result(0, UNCONFIGURED, "")

    ok = Result(0, "Transitioning successful\n", "")
    assert run(processes, "lifecycle", "set", "/lc_talker", "configure") == ok
    assert run(processes, "lifecycle", "set", "/lc_talker", "3") == ok  # an id works too
    assert run(processes, "lifecycle", "get", "lc_talker") == Result(0, "active [3]\n", "")
    assert run(processes, "lifecycle", "list", "/lc_talker") == Result(
        0,
        "- deactivate [4]\n\tStart: active\n\tGoal: deactivating\n"
        "- shutdown [7]\n\tStart: active\n\tGoal: shuttingdown\n",
        "",
    )
    assert run(processes, "lifecycle", "get") == Result(
        0, "/lc_talker: active [3]\n/refuser: unconfigured [1]\n/robot/lc_other: unconfigured [1]\n",
        "",
    )  # fmt: skip
    assert run(processes, "lifecycle", "set", "/lc_talker", "shutdown") == ok
    assert run(processes, "lifecycle", "get", "/lc_talker").out == "finalized [4]\n"
    assert run(processes, "lifecycle", "list", "/lc_talker") == Result(0, "", "")


def test_list_all_shows_the_whole_transition_graph(managed, processes) -> None:
    result = run(processes, "lifecycle", "list", "/robot/lc_other", "-a")

    assert result.code == 0, result
    lines = result.out.splitlines()
    assert len(lines) == 25 * 3
    assert lines[:6] == [
        *UNCONFIGURED.splitlines()[:3],
        *["- transition_success [10]", "\tStart: configuring", "\tGoal: inactive"],
    ]
    assert "- transition_failure [61]" in lines
    assert lines[-3:] == [
        "- transition_error [62]",
        "\tStart: errorprocessing",
        "\tGoal: finalized",
    ]


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["get", "/nobody"], ["Node not found: /nobody"]),
        (["get", "/lc_talke"], ["Node not found: /lc_talke", "did you mean '/lc_talker'"]),
        (
            ["list", "/plain"],
            ["Node not found: /plain is not a lifecycle node", "serves no /plain/get_state"],
        ),
        (["set", "/plain", "configure"], ["Node not found: /plain is not a lifecycle node"]),
        (
            ["set", "/lc_talker", "activate"],
            ["Unknown transition requested, available ones are: configure [1], shutdown [5]"],
        ),
        (["set", "/lc_talker", "7"], ["Unknown transition requested"]),
        (["set", "/refuser", "configure"], ["Transitioning failed"]),
    ],
    ids=["unknown", "typo", "plain-list", "plain-set", "not-offered", "not-offered-id", "refused"],
)
def test_bad_requests_are_one_line_and_exit_1(managed, processes, args, fragments) -> None:
    assert_user_error(run(processes, "lifecycle", *args), *fragments)


def test_refused_transition_leaves_the_node_where_it_was(managed, processes) -> None:
    assert run(processes, "lifecycle", "set", "/refuser", "configure").code == 1
    assert run(processes, "lifecycle", "get", "/refuser").out == "unconfigured [1]\n"


def test_node_info_lists_the_lifecycle_services_and_event_topic(managed, processes) -> None:
    out = run(processes, "node", "info", "/lc_talker").out

    assert "    /lc_talker/transition_event: lifecycle_msgs/msg/TransitionEvent" in out
    for name, kind in [
        ("change_state", "ChangeState"), ("get_available_states", "GetAvailableStates"),
        ("get_available_transitions", "GetAvailableTransitions"), ("get_state", "GetState"),
        ("get_transition_graph", "GetAvailableTransitions"),
    ]:  # fmt: skip
        assert f"    /lc_talker/{name}: lifecycle_msgs/srv/{kind}" in out, out


STUCK = """
import time
import rosl.compat; rosl.compat.install(force=True)
import rclpy
from rclpy.lifecycle import Node

class Stuck(Node):
    def _on_get_state(self, request, response):  # a node too busy to answer
        time.sleep(60)
        return response

rclpy.init()
rclpy.spin(Stuck("stuck"))
"""


def test_get_of_every_node_reports_one_that_does_not_answer_and_goes_on(managed, processes) -> None:
    processes.python(STUCK)
    wait_graph(lambda g: g.count(SERVER, "/stuck/get_transition_graph") == 1)

    result = run(processes, "lifecycle", "get", "--timeout", "1")

    assert result.code == 0, result
    assert result.out == (
        "/lc_talker: unconfigured [1]\n/refuser: unconfigured [1]\n"
        "/robot/lc_other: unconfigured [1]\n"
    )
    assert result.err == (
        "Exception while calling service of node '/stuck': service /stuck/get_state did not "
        "answer within 1 s\n"
    )
    assert_user_error(
        run(processes, "lifecycle", "get", "/stuck", "--timeout", "1"),
        "service /stuck/get_state did not answer within 1 s",
    )
