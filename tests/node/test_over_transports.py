"""Nodes and the graph behave the same over every transport of the seam.

Each test runs two contexts (two participants, as two processes would have) in this process,
once over UDP multicast and once over the in-process transport, so node/ and graph/ are
proven to need nothing but the seam.
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING, Any

import pytest

from rosl.executor import SingleThreadedExecutor
from rosl.node.context import Context
from rosl.node.node import Node

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

BOUND = 15.0  # seconds: only a broken transport or node layer takes this long


@pytest.fixture(params=["multicast", "inprocess"])
def contexts(
    request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch, domain_id: int
) -> Iterator[Callable[[], Context]]:
    """Make initialised contexts on the test's domain and transport; all shut down after."""
    monkeypatch.setenv("ROSL_TRANSPORT", request.param)
    kinds = {"multicast": "Multicast", "inprocess": "InProcess"}
    made: list[Context] = []

    def make() -> Context:
        context = Context()
        context.init([], domain_id=domain_id)
        made.append(context)
        transport = context.ensure_participant().transport
        assert type(transport).__name__ == f"{kinds[request.param]}Transport"
        return context

    yield make
    for context in reversed(made):
        context.try_shutdown()


class Spinner:
    """Spins one node's executor on a thread until stopped."""

    def __init__(self, node: Node) -> None:
        self.executor = SingleThreadedExecutor(context=node.context)
        self.executor.add_node(node)
        self._stop = False
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop and self.executor.context.ok():
            self.executor.spin_once(timeout_sec=0.05)

    def stop(self) -> None:
        self._stop = True
        self._thread.join(BOUND)


def wait_until(predicate: Callable[[], bool], step: Callable[[], Any] | None = None) -> bool:
    deadline = time.monotonic() + BOUND
    while time.monotonic() < deadline:
        if predicate():
            return True
        if step is not None:
            step()
        time.sleep(0.01)
    return predicate()


def test_a_subscription_gets_what_a_publisher_of_another_participant_sends(
    contexts: Callable[[], Context],
) -> None:
    from std_msgs.msg import String

    talker = Node("talker", context=contexts())
    listener = Node("listener", context=contexts())
    heard: list[str] = []
    listener.create_subscription(String, "chatter", lambda m: heard.append(m.data), 10)
    publisher = talker.create_publisher(String, "chatter", 10)
    spinner = Spinner(listener)
    try:
        count = iter(range(10**6))
        assert wait_until(
            lambda: len(heard) >= 3,
            lambda: publisher.publish(String(data=f"hello {next(count)}")),
        ), heard
    finally:
        spinner.stop()
    numbers = [int(text.split()[1]) for text in heard]
    assert numbers == sorted(numbers)  # in order, none twice


def test_a_client_gets_the_answer_of_a_service_of_another_participant(
    contexts: Callable[[], Context],
) -> None:
    from example_interfaces.srv import AddTwoInts

    server = Node("adder", context=contexts())
    caller = Node("caller", context=contexts())

    def add(request: Any, response: Any) -> Any:
        response.sum = request.a + request.b
        return response

    server.create_service(AddTwoInts, "add_two_ints", add)
    client = caller.create_client(AddTwoInts, "add_two_ints")
    spinner = Spinner(server)
    try:
        assert client.wait_for_service(timeout_sec=BOUND)
        answer = client.call(AddTwoInts.Request(a=2, b=40), timeout_sec=BOUND)
    finally:
        spinner.stop()
    assert answer.sum == 42


def test_a_parameter_is_read_through_the_standard_service_of_another_participant(
    contexts: Callable[[], Context],
) -> None:
    from rcl_interfaces.srv import GetParameters

    owner = Node("owner", context=contexts())
    owner.declare_parameter("rate", 7.5)
    asker = Node("asker", context=contexts())
    client = asker.create_client(GetParameters, "/owner/get_parameters")
    spinner = Spinner(owner)
    try:
        assert client.wait_for_service(timeout_sec=BOUND)
        answer = client.call(GetParameters.Request(names=["rate"]), timeout_sec=BOUND)
    finally:
        spinner.stop()
    assert [value.double_value for value in answer.values] == [7.5]


def test_the_graph_shows_another_participants_node_and_topic_and_its_departure(
    contexts: Callable[[], Context],
) -> None:
    from std_msgs.msg import String

    theirs = contexts()
    node = Node("announcer", namespace="/seam", context=theirs)
    node.create_publisher(String, "news", 10)
    mine = contexts()
    observer = Node("observer", context=mine)
    graph = observer.participant.graph

    def seen() -> bool:
        return "/seam/announcer" in {n.fqn for n in graph.nodes()} and graph.topics().get(
            "/seam/news"
        ) == ["std_msgs/msg/String"]

    assert graph.wait_for(seen, BOUND), graph.topics()
    theirs.shutdown()
    assert graph.wait_for(lambda: "/seam/announcer" not in {n.fqn for n in graph.nodes()}, BOUND), [
        n.fqn for n in graph.nodes()
    ]
