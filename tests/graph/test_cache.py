"""The graph cache on its own: updates, goodbyes, liveliness with a fake clock, and queries."""

from __future__ import annotations

import threading
import time

from rosl.graph.cache import LEASE_S, GraphCache
from rosl.graph.records import (
    CLIENT,
    PUBLISHER,
    SERVER,
    SUBSCRIPTION,
    EndpointRecord,
    NodeRecord,
    ProcessRecord,
)

STRING = "std_msgs/msg/String"
INT32 = "std_msgs/msg/Int32"
TRIGGER = "std_srvs/srv/Trigger"


def node(
    sender: int, index: int, name: str, *endpoints: EndpointRecord, ns: str = "/"
) -> NodeRecord:
    return NodeRecord(name, ns, sender, index, endpoints)


def process(sender: int, *nodes: NodeRecord, seen: float = 0.0, version: int = 1) -> ProcessRecord:
    return ProcessRecord(sender, 1000 + sender, "host", nodes, version, seen)


def ep(kind: str, name: str, type_: str, number: int = 1, **stats: int) -> EndpointRecord:
    return EndpointRecord(kind, name, type_, number, {}, dict(stats))


def test_the_default_lease_is_three_and_a_half_seconds() -> None:
    assert LEASE_S == 3.5
    assert GraphCache().lease_s == LEASE_S


def test_a_new_process_changes_the_graph_and_a_repeated_announcement_does_not() -> None:
    cache = GraphCache()
    talker = node(1, 1, "talker", ep(PUBLISHER, "/chatter", STRING))

    assert cache.update(process(1, talker, seen=10.0, version=1)) is True
    assert cache.generation == 1
    assert cache.update(process(1, talker, seen=11.0, version=2)) is False
    assert cache.generation == 1
    assert cache.processes()[0].seen == 11.0  # but the lease is renewed


def test_new_endpoints_change_the_graph() -> None:
    cache = GraphCache()
    cache.update(process(1, node(1, 1, "talker")))
    changed = cache.update(process(1, node(1, 1, "talker", ep(PUBLISHER, "/chatter", STRING))))
    assert changed is True
    assert cache.generation == 2


def test_new_stats_are_stored_without_counting_as_a_graph_change() -> None:
    cache = GraphCache()
    cache.update(process(1, node(1, 1, "l", ep(SUBSCRIPTION, "/t", STRING, received=1))))
    changed = cache.update(process(1, node(1, 1, "l", ep(SUBSCRIPTION, "/t", STRING, received=9))))
    assert changed is False
    assert cache.endpoints(SUBSCRIPTION, "/t")[0][1].stats == {"received": 9}


def test_a_goodbye_removes_the_process_and_bumps_the_generation() -> None:
    cache = GraphCache()
    cache.update(process(1, node(1, 1, "a")))
    cache.update(process(2, node(2, 1, "b")))
    before = cache.generation

    cache.remove(1)

    assert [n.name for n in cache.nodes()] == ["b"]
    assert cache.senders() == {2}
    assert cache.generation == before + 1
    cache.remove(1)  # already gone: nothing changes
    cache.remove(99)
    assert cache.generation == before + 1


def test_processes_past_their_lease_are_dropped_and_returned() -> None:
    cache = GraphCache(lease_s=3.5)
    cache.update(process(1, node(1, 1, "old"), seen=100.0))
    cache.update(process(2, node(2, 1, "fresh"), seen=102.0))
    before = cache.generation

    assert cache.expire(now=103.0) == []  # both within their lease
    assert cache.generation == before

    gone = cache.expire(now=104.0)  # 4.0 s since "old" was heard, 2.0 s since "fresh"

    assert [p.sender for p in gone] == [1]
    assert [n.name for n in cache.nodes()] == ["fresh"]
    assert cache.generation == before + 1

    gone = cache.expire(now=106.0)
    assert [p.sender for p in gone] == [2]
    assert cache.nodes() == []
    assert cache.generation == before + 2


def test_a_process_heard_again_keeps_its_place_in_the_graph() -> None:
    cache = GraphCache(lease_s=3.5)
    cache.update(process(1, node(1, 1, "a"), seen=100.0))
    cache.update(process(1, node(1, 1, "a"), seen=103.0))  # its next announcement
    assert cache.expire(now=106.0) == []
    assert cache.expire(now=106.6) != []


def test_expire_without_a_time_uses_the_monotonic_clock() -> None:
    cache = GraphCache(lease_s=3.5)
    now = time.monotonic()
    cache.update(process(1, node(1, 1, "stale"), seen=now - 10.0))
    cache.update(process(2, node(2, 1, "live"), seen=now))
    assert [p.sender for p in cache.expire()] == [1]
    assert [n.name for n in cache.nodes()] == ["live"]


def crowded_cache() -> GraphCache:
    cache = GraphCache()
    cache.update(
        process(
            1,
            node(
                1,
                1,
                "talker",
                ep(PUBLISHER, "/chatter", STRING, 1),
                ep(SERVER, "/reset", TRIGGER, 2),
            ),
            node(1, 2, "counter", ep(PUBLISHER, "/chatter", INT32, 3)),
        )
    )
    cache.update(
        process(
            2,
            node(2, 1, "listener", ep(SUBSCRIPTION, "/chatter", STRING, 1),
                 ep(SUBSCRIPTION, "/other", INT32, 2), ep(CLIENT, "/reset", TRIGGER, 3),
                 ep(CLIENT, "/missing", TRIGGER, 4), ns="/ns"),
        )
    )  # fmt: skip
    return cache


def test_topics_aggregate_the_types_of_publishers_and_subscriptions() -> None:
    assert crowded_cache().topics() == {"/chatter": [INT32, STRING], "/other": [INT32]}


def test_services_aggregate_the_types_of_servers_and_clients() -> None:
    assert crowded_cache().services() == {"/missing": [TRIGGER], "/reset": [TRIGGER]}


def test_count_counts_endpoints_of_one_kind_on_one_name() -> None:
    cache = crowded_cache()
    assert cache.count(PUBLISHER, "/chatter") == 2
    assert cache.count(SUBSCRIPTION, "/chatter") == 1
    assert cache.count(SUBSCRIPTION, "/nothing") == 0
    assert cache.clients("/reset") == 1
    assert cache.has_server("/reset") is True
    assert cache.has_server("/missing") is False


def test_nodes_are_listed_by_fully_qualified_name_with_their_owners() -> None:
    cache = crowded_cache()
    assert [n.fqn for n in cache.nodes()] == ["/counter", "/ns/listener", "/talker"]
    owners = {(n.fqn, e.name) for n, e in cache.endpoints(PUBLISHER)}
    assert owners == {("/talker", "/chatter"), ("/counter", "/chatter")}


def test_find_node_returns_every_node_sharing_a_name() -> None:
    cache = GraphCache()
    cache.update(process(1, node(1, 1, "twin")))
    cache.update(process(2, node(2, 1, "twin"), node(2, 2, "other")))

    twins = cache.find_node("/twin")

    assert len(twins) == 2
    assert {t.key for t in twins} == {(1, 1), (2, 1)}
    assert cache.find_node("/nobody") == []


def test_wait_for_wakes_when_the_graph_changes() -> None:
    cache = GraphCache()
    woke: list[bool] = []
    waiter = threading.Thread(
        target=lambda: woke.append(cache.wait_for(lambda: bool(cache.find_node("/late")), 10.0))
    )
    waiter.start()
    time.sleep(0.05)
    assert woke == []  # still waiting
    cache.update(process(1, node(1, 1, "unrelated")))
    time.sleep(0.05)
    assert woke == []  # woke up, predicate still false, waits again
    cache.update(process(2, node(2, 1, "late")))
    waiter.join(timeout=5)
    assert woke == [True]


def test_wait_for_gives_up_at_its_timeout() -> None:
    cache = GraphCache()
    assert cache.wait_for(lambda: bool(cache.nodes()), 0.05) is False


def test_wait_change_returns_the_new_generation_after_a_change() -> None:
    cache = GraphCache()
    timer = threading.Timer(0.05, lambda: cache.update(process(1, node(1, 1, "a"))))
    timer.start()
    try:
        assert cache.wait_change(0, timeout=10.0) == 1
    finally:
        timer.cancel()
    assert cache.wait_change(1, timeout=0.01) == 1  # nothing new: the same generation
