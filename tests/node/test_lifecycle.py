"""Managed nodes (rclpy.lifecycle) as rclpy and rcl_lifecycle specify them.

The state machine and callbacks (what rclpy's test_lifecycle.py checks), the lifecycle
publisher over the bus, and the lifecycle services and transition events of a node in another
process, called from this one.
"""

from __future__ import annotations

import pytest

from tests.node.helpers import spin_until

MANAGED_TALKER = """
import rosl.compat; rosl.compat.install(force=True)
import rclpy
from rclpy.lifecycle import Node, TransitionCallbackReturn

class Talker(Node):
    def on_configure(self, state):
        print(f"on_configure from {state.label} [{state.state_id}]", flush=True)
        return TransitionCallbackReturn.SUCCESS

rclpy.init()
node = Talker("managed")
print("ready", flush=True)
rclpy.spin(node)
"""

ALL_STATES = {
    "unknown", "unconfigured", "inactive", "active", "finalized", "configuring", "cleaningup",
    "shuttingdown", "activating", "deactivating", "errorprocessing",
}  # fmt: skip


@pytest.fixture
def lifecycle(ros):
    """rclpy.lifecycle (the alias of rosl's), with rosl initialized."""
    import rosl.compat

    rosl.compat.install(force=True)
    import rclpy.lifecycle

    return rclpy.lifecycle


def state(node):
    return node._state_machine.current_state


def test_transitions_back_and_forth_end_where_rcl_lifecycle_says(lifecycle):
    success = lifecycle.TransitionCallbackReturn.SUCCESS
    node = lifecycle.LifecycleNode("machine", enable_communication_interface=False)
    assert state(node) == (1, "unconfigured")

    assert node.trigger_configure() == success
    for _ in range(3):
        assert node.trigger_cleanup() == success
        assert node.trigger_configure() == success
    assert state(node) == (2, "inactive")
    for _ in range(3):
        assert node.trigger_activate() == success
        assert state(node) == (3, "active")
        assert node.trigger_deactivate() == success
    assert node.trigger_activate() == success
    assert node.trigger_shutdown() == success  # from active: active_shutdown [7]
    assert state(node) == (4, "finalized")
    assert node.trigger_shutdown() is None  # no shutdown from finalized


def test_a_transition_that_does_not_start_in_the_current_state_raises(lifecycle):
    node = lifecycle.LifecycleNode("machine", enable_communication_interface=False)

    with pytest.raises(RuntimeError, match="No transition matching 3 found for current state "
                       "unconfigured"):  # fmt: skip
        node.trigger_activate()
    assert state(node) == (1, "unconfigured")


@pytest.mark.parametrize(
    ("configure", "on_error", "outcome", "end"),
    [
        ("FAILURE", None, "FAILURE", "unconfigured"),  # configure_failure: back where it was
        ("ERROR", None, "ERROR", "unconfigured"),  # on_error's SUCCESS: unconfigured
        ("ERROR", "ERROR", "ERROR", "finalized"),  # on_error fails too: finalized
        ("raise", None, "ERROR", "unconfigured"),  # a callback that raises answers ERROR
        ("None", None, "ERROR", "unconfigured"),  # so does one answering no outcome
    ],
)
def test_callback_outcomes_and_error_processing(lifecycle, configure, on_error, outcome, end):
    answer = lifecycle.TransitionCallbackReturn
    seen = []

    class Node(lifecycle.Node):
        def on_configure(self, state):
            seen.append(("configure", state.label))
            if configure == "raise":
                raise ValueError("no config file")
            return None if configure == "None" else answer[configure]

        def on_error(self, state):
            seen.append(("error", state.label))
            return answer[on_error] if on_error else answer.SUCCESS

    node = Node("machine", enable_communication_interface=False)

    assert node.trigger_configure() == answer[outcome]
    assert state(node)[1] == end
    errored = outcome == "ERROR"
    assert seen == [("configure", "unconfigured")] + ([("error", "unconfigured")] * errored)


def test_the_interface_is_only_made_on_request_and_must_be_a_bool(lifecycle):
    quiet = lifecycle.LifecycleNode("quiet", enable_communication_interface=False)
    served = lifecycle.LifecycleNode("served")

    def lifecycle_services(node):
        names = (s.service_name for s in node.services)
        return sorted(n for n in names if "state" in n or "transition" in n)

    assert lifecycle_services(quiet) == []
    assert not hasattr(quiet, "_service_change_state")
    assert lifecycle_services(served) == [
        "/served/change_state", "/served/get_available_states",
        "/served/get_available_transitions", "/served/get_state", "/served/get_transition_graph",
    ]  # fmt: skip
    assert "/served/transition_event" in {p.topic for p in served.publishers}
    with pytest.raises(TypeError):
        lifecycle.LifecycleNode("bad", enable_communication_interface="asd")
    with pytest.raises(TypeError, match="publisher_class"):
        served.create_lifecycle_publisher(object, "x", 10, publisher_class=object)


def test_a_lifecycle_publisher_sends_only_while_its_node_is_active(lifecycle, ros):
    import rclpy.publisher
    from std_msgs.msg import String

    talker = lifecycle.LifecycleNode("lc_talker", enable_communication_interface=False)
    publisher = talker.create_lifecycle_publisher(String, "lifecycle_chatter", 10)
    listener = ros.Node("listener")
    heard = []
    listener.create_subscription(String, "lifecycle_chatter", lambda m: heard.append(m.data), 10)
    assert isinstance(publisher, rclpy.publisher.Publisher)
    assert isinstance(publisher, lifecycle.Publisher)
    assert spin_until(listener, lambda: publisher.get_subscription_count() > 0, 15.0)

    publisher.publish(String(data="unconfigured"))
    talker.trigger_configure()
    publisher.publish(String(data="inactive"))
    assert not publisher.is_activated
    talker.trigger_activate()
    assert publisher.is_activated
    assert spin_until(listener, lambda: "active" in heard, 15.0,
                      each=lambda: publisher.publish(String(data="active")))  # fmt: skip
    talker.trigger_deactivate()
    publisher.publish(String(data="deactivated"))
    count = len(heard)
    talker.trigger_activate()
    assert spin_until(listener, lambda: "again" in heard, 15.0,
                      each=lambda: publisher.publish(String(data="again")))  # fmt: skip

    # what was published while not active never went out (later messages of the same
    # publisher arrived, so earlier ones would have arrived before them)
    assert set(heard) == {"active", "again"}
    assert heard[count] == "again"


def test_the_lifecycle_services_of_a_node_in_another_process(ros, spawn):
    from lifecycle_msgs.msg import State, TransitionEvent
    from lifecycle_msgs.srv import (
        ChangeState,
        GetAvailableStates,
        GetAvailableTransitions,
        GetState,
    )

    child = spawn(MANAGED_TALKER)
    child.expect("^ready$")
    node = ros.Node("manager")
    events = []
    node.create_subscription(TransitionEvent, "/managed/transition_event", events.append, 10)
    clients = {
        name: node.create_client(kind, f"/managed/{name}")
        for name, kind in [
            ("get_state", GetState),
            ("change_state", ChangeState),
            ("get_available_states", GetAvailableStates),
            ("get_available_transitions", GetAvailableTransitions),
            ("get_transition_graph", GetAvailableTransitions),
        ]
    }
    for client in clients.values():
        assert client.wait_for_service(timeout_sec=20.0), client.srv_name

    def call(name, request=None):
        client = clients[name]
        return client.call(request or client.srv_type.Request(), timeout_sec=15.0)

    assert call("get_state").current_state == State(id=1, label="unconfigured")
    configure = ChangeState.Request()
    configure.transition.id = 1
    assert call("change_state", configure).success
    child.expect(r"^on_configure from unconfigured \[1\]$")
    assert call("get_state").current_state == State(id=2, label="inactive")
    assert {s.label for s in call("get_available_states").available_states} == ALL_STATES
    offered = call("get_available_transitions").available_transitions
    assert [(t.transition.label, t.transition.id, t.goal_state.label) for t in offered] == [
        ("cleanup", 2, "cleaningup"), ("activate", 3, "activating"), ("shutdown", 6, "shuttingdown")
    ]  # fmt: skip
    graph = call("get_transition_graph").available_transitions
    assert {t.transition.label for t in graph} == {
        "configure", "activate", "cleanup", "shutdown", "deactivate", "transition_error",
        "transition_failure", "transition_success",
    }  # fmt: skip
    assert len(graph) == 25
    by_label = ChangeState.Request()
    by_label.transition.label = "activate"
    assert call("change_state", by_label).success
    refused = ChangeState.Request()
    refused.transition.id = 1  # configure: not from active
    assert not call("change_state", refused).success
    assert call("get_state").current_state.label == "active"

    assert spin_until(node, lambda: len(events) >= 4, 15.0)
    assert [(e.start_state.label, e.goal_state.label) for e in events] == [
        ("unconfigured", "configuring"), ("configuring", "inactive"),
        ("inactive", "activating"), ("activating", "active"),
    ]  # fmt: skip
    assert (events[0].timestamp, events[0].transition.id, events[0].transition.label) == (0, 0, "")


def test_destroying_twice_or_nothing_is_false_as_in_rclpy(lifecycle):
    from std_msgs.msg import String

    # ros2/demos' lifecycle talker destroys its timer and publisher in on_cleanup, and again
    # in on_shutdown (None if it was never configured): rclpy answers False, nothing raises
    class Talker(lifecycle.Node):
        timer = publisher = None

        def on_configure(self, state):
            self.publisher = self.create_lifecycle_publisher(String, "chatter", 10)
            self.timer = self.create_timer(1.0, lambda: None)
            return lifecycle.TransitionCallbackReturn.SUCCESS

        def on_cleanup(self, state):
            assert self.destroy_timer(self.timer)
            assert self.destroy_publisher(self.publisher)
            return lifecycle.TransitionCallbackReturn.SUCCESS

        def on_shutdown(self, state):
            assert not self.destroy_timer(self.timer)
            assert not self.destroy_publisher(self.publisher)
            return lifecycle.TransitionCallbackReturn.SUCCESS

    never = Talker("never", enable_communication_interface=False)
    assert never.trigger_shutdown() == lifecycle.TransitionCallbackReturn.SUCCESS
    talker = Talker("talker", enable_communication_interface=False)
    talker.trigger_configure()
    assert talker.trigger_cleanup() == lifecycle.TransitionCallbackReturn.SUCCESS
    assert talker.trigger_shutdown() == lifecycle.TransitionCallbackReturn.SUCCESS
    assert state(talker) == (4, "finalized")
    assert not talker.destroy_subscription(None)
    assert not talker.destroy_client(None)
    assert not talker.destroy_service(None)


def test_a_lifecycle_publisher_made_while_active_waits_for_the_next_activate(lifecycle):
    from std_msgs.msg import String

    node = lifecycle.LifecycleNode("late", enable_communication_interface=False)
    node.trigger_configure()
    node.trigger_activate()
    late = node.create_lifecycle_publisher(String, "late", 10)

    assert not late.is_activated  # rclpy enables managed entities in on_activate only
    node.trigger_deactivate()
    node.trigger_activate()
    assert late.is_activated
    assert node.destroy_lifecycle_publisher(late)
    node.trigger_deactivate()
    assert late.is_activated  # no longer managed: the node leaves it alone
