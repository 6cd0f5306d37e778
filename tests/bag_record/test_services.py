"""``--include-services``: service traffic as ROS 2 (Jazzy) service introspection events.

A server of /add_two_ints and a client making two calls run while ``rosl bag record -a
--include-services`` records (and, alongside, ``rosl bag record -a`` without the flag).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from rosl.idl.idl_text import full_idl
from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path

    from tests.bag_record.conftest import ServiceBag
    from tests.conftest import Processes

EVENT_TOPIC = "/add_two_ints/_service_event"
EVENT_TYPE = "example_interfaces/srv/AddTwoInts_Event"
REQUEST_SENT, RESPONSE_SENT = 0, 2


def events(bag: ServiceBag) -> list[support.Read]:
    return support.by_topic(support.read_anyreader(bag.folder))[EVENT_TOPIC]


def test_the_client_made_its_calls(service_bag: ServiceBag) -> None:
    assert [(c["a"], c["b"], c["sum"]) for c in service_bag.calls] == [(2, 3, 5), (-10, 4, -6)]


def test_service_events_are_recorded_on_the_service_event_topic(service_bag: ServiceBag) -> None:
    entries = {
        e["topic_metadata"]["name"]: e
        for e in support.metadata(service_bag.folder)["topics_with_message_count"]
    }
    assert entries[EVENT_TOPIC]["topic_metadata"]["type"] == EVENT_TYPE
    assert entries[EVENT_TOPIC]["message_count"] == 4
    assert entries[EVENT_TOPIC]["topic_metadata"]["serialization_format"] == "cdr"


def test_event_schemas_are_ros2idl_of_the_event_type(service_bag: ServiceBag) -> None:
    schemas = {k: v for f in support.read_mcap(service_bag.folder) for k, v in f.schemas.items()}
    encoding, text = schemas[EVENT_TYPE]
    assert encoding == "ros2idl"
    assert text == full_idl(EVENT_TYPE)
    assert "IDL: service_msgs/msg/ServiceEventInfo\n" in text
    hashes = support.channel_hashes(service_bag.folder)
    assert hashes[EVENT_TOPIC] == support.rihs01(EVENT_TYPE, "ros2idl", text)


def test_requests_and_responses_are_sent_events_carrying_the_values(
    service_bag: ServiceBag,
) -> None:
    found = [m.fields for m in events(service_bag)]
    requests = [e for e in found if e["info"]["event_type"] == REQUEST_SENT]
    responses = [e for e in found if e["info"]["event_type"] == RESPONSE_SENT]
    assert len(requests) == 2
    assert len(responses) == 2
    assert [(e["request"][0]["a"], e["request"][0]["b"]) for e in requests] == [(2, 3), (-10, 4)]
    assert all(e["response"] == [] for e in requests)
    assert [e["response"][0]["sum"] for e in responses] == [5, -6]
    assert all(e["request"] == [] for e in responses)


def test_client_gid_and_sequence_number_pair_each_request_with_its_response(
    service_bag: ServiceBag,
) -> None:
    found = [m.fields for m in events(service_bag)]
    key = {
        (tuple(e["info"]["client_gid"]), e["info"]["sequence_number"]): e for e in found
        if e["info"]["event_type"] == REQUEST_SENT
    }  # fmt: skip
    assert len(key) == 2
    gids = {gid for gid, _ in key}
    assert len(gids) == 1, "one client made both calls"
    assert any(next(iter(gids))), "the client GID is not all zeros"
    for response in (e for e in found if e["info"]["event_type"] == RESPONSE_SENT):
        pair = (tuple(response["info"]["client_gid"]), response["info"]["sequence_number"])
        request = key[pair]["request"][0]
        assert response["response"][0]["sum"] == request["a"] + request["b"]


def test_event_stamps_fall_within_each_call(service_bag: ServiceBag) -> None:
    found = [m.fields for m in events(service_bag)]
    for call, event_type in (
        (c, t) for c in service_bag.calls for t in (REQUEST_SENT, RESPONSE_SENT)
    ):
        matching = [
            e for e in found
            if e["info"]["event_type"] == event_type
            and (e["request"] or e["response"])[0] in (
                {"a": call["a"], "b": call["b"]}, {"sum": call["sum"]},
            )
        ]  # fmt: skip
        assert len(matching) == 1, (call, event_type)
        stamp = matching[0]["info"]["stamp"]
        ns = stamp["sec"] * 1_000_000_000 + stamp["nanosec"]
        assert call["before"] <= ns <= call["after"], (call, event_type, ns)


def test_every_reader_reads_the_service_events(service_bag: ServiceBag) -> None:
    rosbag2 = support.by_topic(support.read_rosbag2(service_bag.folder))[EVENT_TOPIC]
    mcap = support.by_topic([m for f in support.read_mcap(service_bag.folder) for m in f.messages])[
        EVENT_TOPIC
    ]
    anyreader = events(service_bag)
    assert [m.fields for m in rosbag2] == [m.fields for m in anyreader]
    assert [m.fields for m in mcap] == [m.fields for m in anyreader]
    assert [m.sequence for m in mcap] == [1, 2, 3, 4]


def test_without_include_services_no_service_events_are_recorded(
    service_bag: ServiceBag,
) -> None:
    counts = support.topic_counts(service_bag.plain)
    assert counts["/numbers"] == 5
    assert not [t for t in counts if t.endswith("/_service_event")], counts


FAILING_SERVER = r"""
import rosl
from example_interfaces.srv import AddTwoInts

rosl.init([])
node = rosl.Node("picky_adder")


def add(request, response):
    if request.a < 0:
        raise ValueError("no negative numbers")
    response.sum = request.a + request.b
    return response


node.create_service(AddTwoInts, "/add_two_ints", add)
print("READY", flush=True)
rosl.spin(node)
"""

FAILING_CLIENT = r"""
import time
import rosl
from example_interfaces.srv import AddTwoInts
from rosl.node.client import ServiceFailedError

rosl.init([])
node = rosl.Node("picky_client")
client = node.create_client(AddTwoInts, "/add_two_ints")
assert client.wait_for_service(timeout_sec=30.0), "no server"
deadline = time.monotonic() + 30.0
while node.count_subscribers("/add_two_ints/_service_event") < 1:
    assert time.monotonic() < deadline, "the recorder never subscribed to the service events"
    time.sleep(0.02)
time.sleep(0.2)
try:
    client.call(AddTwoInts.Request(a=-1, b=1), timeout_sec=20.0)
except ServiceFailedError as err:
    print("failed", err, flush=True)
print("sum", client.call(AddTwoInts.Request(a=2, b=3), timeout_sec=20.0).sum, flush=True)
rosl.shutdown()
"""


def test_a_failed_call_records_its_request_and_the_recording_goes_on(
    processes: Processes, tmp_path: Path
) -> None:
    folder = tmp_path / "failed_call"
    recorder = support.start_recorder(
        processes, "-a", "--include-services", "-o", str(folder), cwd=tmp_path
    )
    server = support.Child(processes.python(FAILING_SERVER, cwd=tmp_path))
    assert server.wait_for("^READY", timeout=30), server.both()
    client = support.Child(processes.python(FAILING_CLIENT, cwd=tmp_path))
    assert client.finish(60) == 0, client.both()
    assert client.lines() == [
        "failed service /add_two_ints failed: ValueError: no negative numbers",
        "sum 5",
    ], client.both()
    err = support.stop_recorder(recorder)
    assert "Traceback" not in err, err
    assert "WARN" not in err, err
    found = [m.fields for m in support.by_topic(support.read_anyreader(folder))[EVENT_TOPIC]]
    assert [(e["info"]["event_type"], e["request"], e["response"]) for e in found] == [
        (REQUEST_SENT, [{"a": -1, "b": 1}], []),
        (REQUEST_SENT, [{"a": 2, "b": 3}], []),
        (RESPONSE_SENT, [], [{"sum": 5}]),
    ]
