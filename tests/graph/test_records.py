"""Discovery records: the JSON wire form, GIDs, hidden names."""

from __future__ import annotations

import json
import re

import pytest

from rosl.graph.records import (
    CLIENT,
    PUBLISHER,
    SERVER,
    SUBSCRIPTION,
    EndpointRecord,
    NodeRecord,
    ProcessRecord,
    from_json,
    gid,
    is_hidden,
    to_json,
)

SENDER = 0xFEDCBA9876543211  # high bit set: must survive the hex text form


def sample_process(sender: int = SENDER, seen: float = 0.0) -> ProcessRecord:
    talker = NodeRecord(
        "talker",
        "/demo",
        sender,
        1,
        (
            EndpointRecord(
                PUBLISHER, "/demo/chatter", "std_msgs/msg/String", 1,
                {"reliability": "BEST_EFFORT", "durability": "VOLATILE", "depth": 7},
                {"sent": 12},
            ),
            EndpointRecord(
                SUBSCRIPTION, "/numbers", "std_msgs/msg/Int32", 2,
                {"durability": "TRANSIENT_LOCAL", "depth": 3},
                {"received": 5, "lost": 1, "mismatched": 0},
            ),
            EndpointRecord(SERVER, "/demo/reset", "std_srvs/srv/Trigger", 3, {}, {"handled": 2}),
            EndpointRecord(CLIENT, "/add", "example_interfaces/srv/AddTwoInts", 4),
        ),
    )  # fmt: skip
    quiet = NodeRecord("quiet", "/", sender, 2)
    return ProcessRecord(sender, 4242, "robot-1", (talker, quiet), 17, seen)


def full_fields(endpoint: EndpointRecord) -> tuple[object, ...]:
    """Every field, including the ones equality ignores (qos, stats)."""
    return (endpoint.kind, endpoint.name, endpoint.type, endpoint.endpoint, endpoint.qos,
            endpoint.stats)  # fmt: skip


def test_a_process_record_survives_the_json_wire_form_unchanged() -> None:
    original = sample_process()
    wire = json.loads(json.dumps(to_json(original)))  # really through JSON text

    decoded = from_json(wire, seen=123.5)

    assert decoded.sender == SENDER
    assert (decoded.pid, decoded.host, decoded.version) == (4242, "robot-1", 17)
    assert decoded.seen == 123.5
    assert decoded.nodes == original.nodes
    for got, want in zip(decoded.nodes, original.nodes, strict=True):
        assert (got.name, got.namespace, got.process, got.index) == (
            want.name, want.namespace, want.process, want.index,
        )  # fmt: skip
        assert [full_fields(e) for e in got.endpoints] == [full_fields(e) for e in want.endpoints]


def test_the_sender_is_written_as_sixteen_hex_digits() -> None:
    assert to_json(sample_process(sender=1))["sender"] == "0000000000000001"
    assert to_json(sample_process())["sender"] == f"{SENDER:016x}"


def test_decoded_nodes_belong_to_the_announcing_process() -> None:
    wire = to_json(sample_process())
    decoded = from_json(wire, seen=0.0)
    assert {node.process for node in decoded.nodes} == {SENDER}
    assert [node.key for node in decoded.nodes] == [(SENDER, 1), (SENDER, 2)]


@pytest.mark.parametrize(
    "breakage",
    [
        lambda d: d.pop("sender"),
        lambda d: d.update(sender="not hex"),
        lambda d: d.update(nodes=[{"name": "x"}]),
        lambda d: d["nodes"][0].update(endpoints=[["publisher", "/t"]]),
        lambda d: d.update(pid="many"),
    ],
    ids=["no sender", "bad sender", "node without fields", "short endpoint", "bad pid"],
)
def test_malformed_wire_data_raises_a_decoding_error(breakage: object) -> None:
    wire = to_json(sample_process())
    breakage(wire)  # type: ignore[operator]
    with pytest.raises((KeyError, TypeError, ValueError)):
        from_json(wire, seen=0.0)


def test_a_gid_is_sixteen_dot_joined_two_digit_hex_bytes() -> None:
    text = gid(SENDER, 5)
    assert re.fullmatch(r"[0-9a-f]{2}(\.[0-9a-f]{2}){15}", text), text


def test_a_gid_holds_the_process_id_then_the_endpoint_little_endian_then_zeros() -> None:
    assert gid(0x0102030405060708, 0x0A0B) == ("08.07.06.05.04.03.02.01.0b.0a.00.00.00.00.00.00")
    assert gid(1, 1) != gid(1, 2)
    assert gid(1, 1) != gid(2, 1)


@pytest.mark.parametrize(
    ("name", "hidden"),
    [
        ("/chatter", False),
        ("/ns/chatter", False),
        ("/my_topic", False),
        ("/a_/b", False),
        ("", False),
        ("/", False),
        ("/_hidden", True),
        ("/ns/_private", True),
        ("/_ns/visible", True),
        ("/talker/_action/status", True),
        ("_relative", True),
    ],
)
def test_a_name_is_hidden_when_any_token_starts_with_an_underscore(name: str, hidden: bool) -> None:
    assert is_hidden(name) is hidden


@pytest.mark.parametrize(
    ("namespace", "fqn"), [("/", "/talker"), ("/demo", "/demo/talker"), ("/a/b/", "/a/b/talker")]
)
def test_a_node_fully_qualified_name_joins_namespace_and_name(namespace: str, fqn: str) -> None:
    assert NodeRecord("talker", namespace, 1, 1).fqn == fqn


def test_endpoint_equality_ignores_qos_and_stats() -> None:
    a = EndpointRecord(SUBSCRIPTION, "/t", "std_msgs/msg/Int32", 1, {"depth": 1}, {"received": 1})
    b = EndpointRecord(SUBSCRIPTION, "/t", "std_msgs/msg/Int32", 1, {"depth": 9}, {"received": 9})
    assert a == b
    assert hash(a) == hash(b)
