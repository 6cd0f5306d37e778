"""Discovery between real processes on the bus: announcements, queries, goodbyes, leases."""

from __future__ import annotations

import subprocess
import time
from typing import TYPE_CHECKING

import pytest

from rosl.graph.cache import LEASE_S
from rosl.graph.records import CLIENT, PUBLISHER, SERVER, SUBSCRIPTION
from tests.conftest import wait_until
from tests.graph.support import SPIN_NODES, leaving_time, wait_for_node

if TYPE_CHECKING:
    from collections.abc import Callable

    from rosl.node.participant import Participant
    from tests.graph.support import Watched

ENDPOINTS_CHILD = """
import rosl
from example_interfaces.srv import AddTwoInts
from rosl.node.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Int32, String
from std_srvs.srv import Trigger

rosl.init([])
node = rosl.Node("talker", namespace="/demo")
node.create_publisher(String, "chatter", QoSProfile(depth=7, reliability=ReliabilityPolicy.BEST_EFFORT))
node.create_subscription(
    Int32, "/numbers", lambda msg: None,
    QoSProfile(depth=3, durability=DurabilityPolicy.TRANSIENT_LOCAL),
)
node.create_service(Trigger, "reset", lambda request, response: response)
node.create_client(AddTwoInts, "/add")
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""

SETTLING_NODES = """
import sys
import rosl

rosl.init([])
expected = int(sys.argv[1])
nodes = [rosl.Node(name) for name in sys.argv[2:]]
graph = nodes[0].participant.graph
# ready once this process has heard every sibling: the graph has settled
settled = graph.wait_for(lambda: len(graph.senders()) >= expected, 40)
print("ready" if settled else "unsettled", flush=True)
executor = rosl.get_global_executor()
for node in nodes:
    executor.add_node(node)
executor.spin()
rosl.shutdown()
"""

LONELY_NODE = """
import sys
import rosl

rosl.init([])
node = rosl.Node(sys.argv[1])
graph = node.participant.graph
# its own announcement comes back: discovery works on its domain
assert graph.wait_for(lambda: bool(graph.find_node(node.fully_qualified)), 20)
print("ready", flush=True)
rosl.spin(node)
print("seen", sorted(n.fqn for n in graph.nodes()), flush=True)
rosl.shutdown()
"""

COUNTING_LISTENER = """
import rosl
from std_msgs.msg import Int32

rosl.init([])
node = rosl.Node("tally")
node.create_subscription(Int32, "/counts", lambda msg: print("got", msg.data, flush=True), 10)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


def endpoint(record: object, kind: str, name: str) -> object:
    found = [e for e in record.endpoints if e.kind == kind and e.name == name]  # type: ignore[attr-defined]
    assert len(found) == 1, f"expected one {kind} on {name}, got {found}"
    return found[0]


def test_a_node_in_another_process_shows_up_with_its_endpoints_types_and_qos(
    watch: Callable[..., Watched], observer: Participant
) -> None:
    child = watch(ENDPOINTS_CHILD)
    child.wait_ready()

    wait_for_node(observer.graph, "/demo/talker")
    # each new endpoint is announced as it comes; wait for the last one the child made
    graph = observer.graph
    assert graph.wait_for(lambda: graph.count(CLIENT, "/add") == 1, 20), graph.nodes()
    (talker,) = graph.find_node("/demo/talker")

    (owner,) = [p for p in observer.graph.processes() if p.sender == talker.process]
    assert owner.pid == child.pid
    assert (talker.name, talker.namespace) == ("talker", "/demo")

    pub = endpoint(talker, PUBLISHER, "/demo/chatter")
    assert pub.type == "std_msgs/msg/String"
    assert pub.qos["reliability"] == "BEST_EFFORT"
    assert pub.qos["depth"] == 7
    assert pub.qos["durability"] == "VOLATILE"
    assert pub.qos["history"] == "KEEP_LAST"

    sub = endpoint(talker, SUBSCRIPTION, "/numbers")
    assert sub.type == "std_msgs/msg/Int32"
    assert sub.qos["durability"] == "TRANSIENT_LOCAL"
    assert sub.qos["reliability"] == "RELIABLE"
    assert sub.qos["depth"] == 3

    assert endpoint(talker, SERVER, "/demo/reset").type == "std_srvs/srv/Trigger"
    assert endpoint(talker, CLIENT, "/add").type == "example_interfaces/srv/AddTwoInts"
    # every node also serves its parameters and publishes /rosout
    assert endpoint(talker, SERVER, "/demo/talker/set_parameters").type == (
        "rcl_interfaces/srv/SetParameters"
    )
    assert endpoint(talker, PUBLISHER, "/rosout").type == "rcl_interfaces/msg/Log"

    topics = observer.graph.topics()
    assert topics["/demo/chatter"] == ["std_msgs/msg/String"]
    assert topics["/numbers"] == ["std_msgs/msg/Int32"]
    services = observer.graph.services()
    assert services["/demo/reset"] == ["std_srvs/srv/Trigger"]
    assert services["/add"] == ["example_interfaces/srv/AddTwoInts"]


def test_rosl_nodes_see_other_processes_through_the_node_graph_api(
    watch: Callable[..., Watched], ros: object
) -> None:
    child = watch(ENDPOINTS_CHILD)
    child.wait_ready()
    node = ros.Node("looker")  # type: ignore[attr-defined]

    assert node.wait_for_node("/demo/talker", 30.0)
    assert wait_until(lambda: ("/add", ["example_interfaces/srv/AddTwoInts"])
                      in node.get_service_names_and_types())  # fmt: skip
    assert node.count_publishers("/demo/chatter") == 1
    assert node.count_subscribers("/numbers") == 1
    assert ("talker", "/demo") in node.get_node_names_and_namespaces()
    assert ("/demo/chatter", ["std_msgs/msg/String"]) in node.get_topic_names_and_types()
    assert ("/demo/reset", ["std_srvs/srv/Trigger"]) in node.get_service_names_and_types()


def test_a_fresh_participant_query_completes_holding_every_node_of_every_process(
    watch: Callable[..., Watched], domain_id: int
) -> None:
    from rosl.node.participant import Participant

    layout = [["alpha"], ["beta", "gamma"], ["delta"], ["epsilon", "zeta"], ["eta"]]
    children = [watch(SETTLING_NODES, str(len(layout)), *names) for names in layout]
    for child in children:
        child.wait_ready(timeout=60)

    fresh = Participant(domain_id)  # joins now, knowing nothing
    try:
        qid = fresh.discovery.query()
        complete = fresh.discovery.wait_complete(qid, timeout=15.0)
        # no waiting after completion: the graph must already be whole
        names = sorted(n.fqn for n in fresh.graph.nodes())
        pids = {p.pid for p in fresh.graph.processes()}
    finally:
        fresh.close()

    assert complete is True
    assert names == sorted(f"/{name}" for group in layout for name in group)
    assert pids == {child.pid for child in children}


def test_the_query_sent_at_start_completes_with_every_process_without_asking_again(
    watch: Callable[..., Watched], domain_id: int
) -> None:
    from rosl.introspection.session import Session

    layout = [["alpha"], ["beta", "gamma"]]
    children = [watch(SETTLING_NODES, str(len(layout)), *names) for names in layout]
    for child in children:
        child.wait_ready(timeout=60)

    with Session(domain_id) as session:  # a CLI command: its participant asked at start
        discovery = session.participant.discovery
        names = sorted(n.fqn for n in session.graph().nodes())
        queries = sorted(discovery._queries)

    assert names == ["/alpha", "/beta", "/gamma"]
    assert queries == [discovery.first_query]  # one round trip: the one made at start


def test_a_query_with_no_nodes_anywhere_completes_with_an_empty_graph(
    observer: Participant,
) -> None:
    started = time.monotonic()
    qid = observer.discovery.query()
    complete = observer.discovery.wait_complete(qid, timeout=2.0)
    elapsed = time.monotonic() - started

    assert complete is True
    assert elapsed < 2.0 + 10.0  # returned (its bound plus any load), not hung
    assert observer.graph.nodes() == []


def test_a_query_answered_only_by_this_process_completes(ros: object) -> None:
    node = ros.Node("alone")  # type: ignore[attr-defined]
    discovery = node.participant.discovery
    qid = discovery.query()
    assert discovery.wait_complete(qid, timeout=15.0) is True
    assert [n.fqn for n in node.participant.graph.nodes()] == ["/alone"]


def test_a_node_shut_down_with_ctrl_c_leaves_the_graph_at_once_by_saying_goodbye(
    watch: Callable[..., Watched], observer: Participant
) -> None:
    child = watch(SPIN_NODES, "leaver")
    child.wait_ready()
    leaver = wait_for_node(observer.graph, "/leaver")

    timing = leaving_time(observer.graph, leaver.process, child.send, 3 * LEASE_S)

    assert timing is not None, "the node never left the graph"
    last_seen, gone_at = timing
    # gone before its lease could have run out: the goodbye removed it, not liveliness
    assert gone_at - last_seen < LEASE_S
    assert child.interrupt() == 0
    assert "bye" in child.lines("out")
    assert observer.graph.find_node("/leaver") == []  # and no late hello brought it back


@pytest.mark.slow
def test_a_killed_node_stays_until_its_lease_runs_out_then_disappears(
    watch: Callable[..., Watched], observer: Participant
) -> None:
    child = watch(SPIN_NODES, "victim")
    child.wait_ready()
    victim = wait_for_node(observer.graph, "/victim")

    child.child.kill()  # SIGKILL: no goodbye
    child.child.wait(timeout=5)
    # dead, but nothing told the graph: it is still there
    assert observer.graph.find_node("/victim") != []
    (record,) = [p for p in observer.graph.processes() if p.sender == victim.process]
    last_seen = record.seen

    assert wait_until(lambda: observer.graph.find_node("/victim") == [], timeout=20.0), (
        "a killed node was still in the graph 20 s after its death"
    )
    # and it was liveliness that removed it: its lease had run out
    assert time.monotonic() - last_seen > LEASE_S


def test_two_nodes_with_the_same_name_in_two_processes_get_a_warning(
    watch: Callable[..., Watched], observer: Participant
) -> None:
    first = watch(SPIN_NODES, "twin")
    first.wait_ready()
    second = watch(SPIN_NODES, "twin")
    second.wait_ready()

    assert observer.graph.wait_for(lambda: len(observer.graph.find_node("/twin")) == 2, 20)
    twins = observer.graph.find_node("/twin")
    assert len({t.process for t in twins}) == 2

    def warned() -> bool:
        return any(
            "WARN" in line and "/twin" in line
            for child in (first, second)
            for line in child.lines("err")
        )

    assert wait_until(warned, timeout=15.0), (
        f"no duplicate-name warning:\n{first.text('err')}\n---\n{second.text('err')}"
    )
    assert first.interrupt() == 0
    assert second.interrupt() == 0
    for child in (first, second):
        assert "Traceback" not in child.text("err")


def test_a_node_on_another_domain_is_not_seen(
    watch: Callable[..., Watched], observer: Participant, other_domain: int
) -> None:
    near = watch(LONELY_NODE, "near")
    far = watch(LONELY_NODE, "far", env={"ROSL_DOMAIN_ID": str(other_domain)})
    near.wait_ready()
    far.wait_ready()  # it sees itself on its own domain

    wait_for_node(observer.graph, "/near")
    qid = observer.discovery.query()
    assert observer.discovery.wait_complete(qid, timeout=15.0)
    assert observer.graph.find_node("/far") == []
    assert [n.fqn for n in observer.graph.nodes()] == ["/near"]

    assert far.interrupt() == 0
    assert far.matching(r"^seen \['/far'\]$"), far.text("out")  # nor did it see us
    assert near.interrupt() == 0


def test_a_subscription_reports_its_growing_received_count_in_announcements(
    watch: Callable[..., Watched], ros: object
) -> None:
    from std_msgs.msg import Int32

    listener = watch(COUNTING_LISTENER)
    listener.wait_ready()
    node = ros.Node("feeder")  # type: ignore[attr-defined]
    pub = node.create_publisher(Int32, "/counts", 10)
    assert pub.wait_for_subscribers(1, 30.0) == 1
    graph = node.participant.graph

    def stat(kind: str, key: str) -> int:
        found = graph.endpoints(kind, "/counts")
        return found[0][1].stats.get(key, -1) if found else -1

    for value in range(3):
        pub.publish(Int32(data=value))
    assert listener.wait_for(r"^got 2$", timeout=15.0), listener.text("err")
    assert wait_until(lambda: stat(SUBSCRIPTION, "received") == 3, timeout=15.0), graph.endpoints(
        SUBSCRIPTION, "/counts"
    )

    for value in range(3, 7):
        pub.publish(Int32(data=value))
    assert listener.wait_for(r"^got 6$", timeout=15.0)
    assert wait_until(lambda: stat(SUBSCRIPTION, "received") == 7, timeout=15.0)
    assert stat(SUBSCRIPTION, "mismatched") == 0
    # the publisher's own count travels the same way (this process hears itself)
    assert wait_until(lambda: stat(PUBLISHER, "sent") == 7, timeout=15.0)
    assert listener.interrupt() == 0


SLOW_TO_DESCRIBE = """
import subprocess
import time
import rosl

class SlowToDescribe(rosl.Node):
    # describing this node takes a while, as it does for big nodes or a busy interpreter
    def record(self):
        found = super().record()
        time.sleep(0.3)
        return found

rosl.init([])
first = rosl.Node("first")
slow = SlowToDescribe("slow")
print("ready", flush=True)
rosl.spin(first)
first.destroy_node()  # announced at once: the discovery thread starts describing "slow"
time.sleep(0.05)
rosl.shutdown()  # ... and the goodbye goes out while it is still at it
print("bye", flush=True)
"""


def test_a_goodbye_is_not_overtaken_by_an_announcement_still_being_made(
    watch: Callable[..., Watched], observer: Participant
) -> None:
    child = watch(SLOW_TO_DESCRIBE)
    child.wait_ready()
    wait_for_node(observer.graph, "/slow")
    wait_for_node(observer.graph, "/first")

    assert child.interrupt() == 0
    assert "bye" in child.lines("out")
    # let this process read whatever the child sent before it exited: our own query comes
    # back on the same discovery socket after all of it, whatever the machine's load
    observer.discovery.wait_complete(observer.discovery.query(), timeout=5.0)
    # the process said goodbye and exited: nothing of it may linger until its lease runs out
    lingering = [n.fqn for n in observer.graph.nodes()]
    assert lingering == [], (
        f"{lingering} still in the graph after its process said goodbye and exited: an "
        "announcement started before the goodbye was sent after it"
    )


DESTROY_ON_REQUEST = """
import sys
import rosl

rosl.init([])
nodes = {name: rosl.Node(name) for name in sys.argv[1:]}
print("ready", flush=True)
for line in sys.stdin:  # one node name per line: destroy it, the process lives on
    nodes[line.strip()].destroy_node()
    print("destroyed", line.strip(), flush=True)
rosl.shutdown()
"""


def test_a_destroyed_node_leaves_the_graph_while_its_process_keeps_running(
    watch: Callable[..., Watched], observer: Participant
) -> None:
    child = watch(DESTROY_ON_REQUEST, "keeper", "passing", stdin=subprocess.PIPE)
    child.wait_ready()
    wait_for_node(observer.graph, "/keeper")
    wait_for_node(observer.graph, "/passing")

    child.tell("passing")
    assert child.wait_for(r"^destroyed passing$", timeout=15.0)

    graph = observer.graph
    assert graph.wait_for(lambda: graph.find_node("/passing") == [], 15.0)
    assert [n.fqn for n in graph.nodes()] == ["/keeper"]


def test_destroying_the_last_node_of_a_running_process_removes_it_at_once(
    watch: Callable[..., Watched], observer: Participant
) -> None:
    child = watch(DESTROY_ON_REQUEST, "only", stdin=subprocess.PIPE)
    child.wait_ready()
    only = wait_for_node(observer.graph, "/only")

    def destroy() -> None:
        child.tell("only")
        assert child.wait_for(r"^destroyed only$", timeout=15.0)

    timing = leaving_time(observer.graph, only.process, destroy, 3 * LEASE_S)

    assert timing is not None, "/only never left the graph"
    last_seen, gone_at = timing
    assert child.child.poll() is None  # the process is still running
    # the change was announced, not left to the lease (rclpy removes destroyed nodes at once)
    assert gone_at - last_seen < LEASE_S, (
        f"/only stayed in the graph {gone_at - last_seen:.1f} s after its process was last "
        "heard from: the lease removed it, nothing announced that it was destroyed"
    )
