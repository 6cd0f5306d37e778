"""``rosl bridge foxglove`` as Foxglove sees it: a WebSocket client against real processes.

The client speaks the Foxglove WebSocket protocol by hand (JSON ops, binary frames) and decodes
the CDR it gets with rosbags, from the schema text the bridge sent: nothing of rosl's own serde
is trusted to check rosl. The SDK names the subprotocol ``foxglove.sdk.v1``, the new name of
``foxglove.websocket.v1`` (the same messages).
"""

from __future__ import annotations

import contextlib
import functools
import json
import re
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from typing import TYPE_CHECKING, Any

import pytest
import yaml

from rosl.graph.records import PUBLISHER, SUBSCRIPTION
from tests.conftest import REPO, wait_until
from tests.node.helpers import Child, snippet

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator

    from tests.conftest import Processes

websockets_sync = pytest.importorskip("websockets.sync.client")
websockets_exceptions = pytest.importorskip("websockets.exceptions")

SUBPROTOCOL = "foxglove.sdk.v1"
BOUND = 30.0  # seconds: only a broken bridge takes this long
LISTENING = r"listening on ws://127\.0\.0\.1:(\d+)"
WALL_NS = 10**18  # wall-clock nanoseconds are above this (2001 on); sim time starts at 0

TALKER = """
import rosl
from std_msgs.msg import String
rosl.init()
node = rosl.Node("bridge_talker")
publisher = node.create_publisher(String, "/bridge_test", 10)
node.create_timer(0.05, lambda: publisher.publish(String(data="hello bridge")))
print("ready", flush=True)
rosl.spin(node)
"""

LISTENER = """
import rosl
from std_msgs.msg import String
rosl.init()
node = rosl.Node("bridge_listener")
node.create_subscription(String, "/from_foxglove", lambda m: print("got:", m.data, flush=True), 10)
print("ready", flush=True)
rosl.spin(node)
"""

ADDER = """
import rosl
from example_interfaces.srv import AddTwoInts
rosl.init()
node = rosl.Node("adder")
node.declare_parameter("offset", 3)
def add(request, response):
    response.sum = request.a + request.b + node.get_parameter("offset").value
    return response
node.create_service(AddTwoInts, "/add_two_ints", add)
print("ready", flush=True)
rosl.spin(node)
"""


# --- a Foxglove WebSocket client ---------------------------------------------------------------


class FoxgloveClient:
    """What a Foxglove app keeps of one connection: channels, services, messages, times.

    A thread reads the connection all the time, as the app does (the server drops a client
    whose queue of control messages fills up), and subscribes again when a watched topic comes
    back as a new channel (its publisher left the graph and returned), as the app does.
    """

    def __init__(self, port: int) -> None:
        self._stack = contextlib.ExitStack()
        self.ws = self._stack.enter_context(
            websockets_sync.connect(
                f"ws://127.0.0.1:{port}", subprotocols=[SUBPROTOCOL], max_size=None, open_timeout=15
            )
        )
        self.lock = threading.RLock()
        self.info: dict[str, Any] = {}
        self.channels: dict[int, dict[str, Any]] = {}
        self.unadvertised: list[int] = []
        self.services: dict[str, dict[str, Any]] = {}
        self.topics: dict[int, str] = {}  # subscription id -> topic
        self.watching: dict[str, tuple[int, int]] = {}  # topic -> (subscription, channel) ids
        self.messages: dict[str, list[tuple[int, bytes]]] = {}  # topic -> (log time, cdr)
        self.times: list[int] = []
        self.replies: list[dict[str, Any]] = []  # other JSON ops (parameterValues, status...)
        self.responses: dict[int, bytes] = {}  # call id -> response payload
        self._next = 1
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        assert self.wait(lambda: bool(self.info), 15), "no serverInfo"

    def close(self) -> None:
        self._stack.close()
        self._reader.join(BOUND)

    def _read(self) -> None:
        with contextlib.suppress(websockets_exceptions.ConnectionClosed):
            for frame in self.ws:
                with self.lock:
                    if isinstance(frame, str):
                        self._text(json.loads(frame))
                    else:
                        self._binary(frame)

    def _text(self, message: dict[str, Any]) -> None:
        op = message["op"]
        if op == "serverInfo":
            self.info = message
        elif op == "advertise":
            self.channels.update({c["id"]: c for c in message["channels"]})
            for channel in message["channels"]:
                watched = self.watching.get(channel["topic"])
                if watched is not None and watched[1] != channel["id"]:
                    self.subscribe(channel["topic"])
        elif op == "unadvertise":
            self.unadvertised.extend(message["channelIds"])
        elif op == "advertiseServices":
            self.services.update({s["name"]: s for s in message["services"]})
        else:
            self.replies.append(message)

    def _binary(self, frame: bytes) -> None:
        if frame[0] == 0x01:  # message data: subscription id, log time, payload
            sid, log_time = struct.unpack_from("<IQ", frame, 1)
            self.messages.setdefault(self.topics.get(sid, "?"), []).append((log_time, frame[13:]))
        elif frame[0] == 0x02:  # time
            self.times.append(struct.unpack_from("<Q", frame, 1)[0])
        elif frame[0] == 0x03:  # service call response
            _, call, length = struct.unpack_from("<III", frame, 1)
            self.responses[call] = frame[13 + length :]

    def wait(self, predicate: Callable[[], Any], timeout: float = BOUND) -> bool:
        """Whether ``predicate()`` came true within ``timeout`` (checked under the lock)."""
        deadline = time.monotonic() + timeout
        while True:
            with self.lock:
                if predicate():
                    return True
            if time.monotonic() >= deadline:
                return False
            time.sleep(0.02)

    def channel(self, topic: str) -> dict[str, Any] | None:
        """The live channel of ``topic`` (None when not advertised, or taken back)."""
        found = [c for i, c in self.channels.items() if c["topic"] == topic]
        live = [c for c in found if c["id"] not in self.unadvertised]
        return live[-1] if live else None

    def send(self, op: str, **fields: Any) -> None:
        self.ws.send(json.dumps({"op": op, **fields}))

    def subscribe(self, topic: str) -> str:
        with self.lock:
            channel = self.channel(topic)
            assert channel is not None, f"{topic} is not advertised: {self.channels}"
            sid, self._next = self._next, self._next + 1
            self.topics[sid] = topic
            self.watching[topic] = (sid, channel["id"])
        self.send("subscribe", subscriptions=[{"id": sid, "channelId": channel["id"]}])
        return topic

    def unsubscribe(self, topic: str) -> None:
        with self.lock:
            sid, _ = self.watching.pop(topic)
        self.send("unsubscribe", subscriptionIds=[sid])

    def received(self, topic: str) -> list[tuple[int, bytes]]:
        with self.lock:  # a copy: the reader thread goes on appending
            return list(self.messages.get(topic, []))

    def call(self, service: str, payload: bytes) -> int:
        call_id, self._next = self._next, self._next + 1
        encoding = b"cdr"
        head = struct.pack("<BIII", 0x02, self.services[service]["id"], call_id, len(encoding))
        self.ws.send(head + encoding + payload)
        return call_id


@functools.cache
def typestore_from(schema_name: str, text: str) -> tuple[Any, str]:
    """A rosbags typestore knowing a ros2msg schema (its dependencies after ``MSG:`` lines).

    Returns the store and the name rosbags gave the schema's own type (``pkg/srv/X_Request``
    becomes ``pkg/srv/msg/X_Request`` there).
    """
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.EMPTY)
    blocks = re.split(r"^={80}\n", text, flags=re.MULTILINE)
    types = dict(get_types_from_msg(blocks[0], schema_name))
    own = next(iter(types))
    for block in blocks[1:]:
        header, _, body = block.partition("\n")
        package, *_, name = header.removeprefix("MSG: ").strip().split("/")
        types.update(get_types_from_msg(body, f"{package}/msg/{name}"))
    store.register(types)
    return store, own


def decode(client: FoxgloveClient, topic: str, payload: bytes) -> Any:
    """A message of ``topic`` decoded by rosbags from the schema the bridge advertised."""
    channel = client.channel(topic)
    assert channel is not None
    assert (channel["encoding"], channel["schemaEncoding"]) == ("cdr", "ros2msg")
    store, name = typestore_from(channel["schemaName"], channel["schema"])
    return store.deserialize_cdr(payload, name)


# --- processes ----------------------------------------------------------------------------------


def start_bridge(processes: Processes, *args: str) -> tuple[Child, int]:
    """``rosl bridge foxglove --port 0`` and the port it says it listens on."""
    child = Child(processes.rosl("bridge", "foxglove", "--port", "0", *args), processes)
    match = child.wait_for(LISTENING, timeout=BOUND)
    if match is None:
        child.pump()
        raise AssertionError(f"the bridge did not start:\n{child.text}")
    return child, int(match.group(1))


def start_node(processes: Processes, code: str) -> Child:
    child = Child(processes.python(snippet(code)), processes)
    child.expect("ready", timeout=BOUND)
    return child


@pytest.fixture
def session(domain_id: int) -> Iterator[Any]:
    """A graph view of the test's domain, from this process."""
    from rosl.introspection.session import Session

    with Session(domain_id) as found:
        yield found


def bridge_endpoints(session: Any, kind: str) -> set[str]:
    graph = session.graph(fresh=True)
    return {e.name for node, e in graph.endpoints(kind) if node.name == "foxglove_bridge"}


def scan_samples() -> int:
    """The beam count of the TurtleBot3's LiDAR, from its robot file."""
    robot = yaml.safe_load((REPO / "worlds" / "robots" / "turtlebot3_burger.yaml").read_text())
    found = [s for s in robot["sensors"] if s["type"] == "lidar2d"]
    return int(found[0]["samples"])


# --- the tests ----------------------------------------------------------------------------------


@pytest.mark.slow
def test_the_sims_scan_and_odom_arrive_as_cdr_rosbags_decodes_in_sim_time(
    processes: Processes, session: Any
) -> None:
    from rosl.idl import registry

    sim = Child(processes.rosl("sim", "turtlebot3_world", "--headless"), processes)
    sim.expect("is up", stream="err", timeout=BOUND)
    _, port = start_bridge(processes)
    client = FoxgloveClient(port)
    try:
        assert "time" in client.info["capabilities"]
        wanted = ("/scan", "/odom", "/joint_states", "/robot_description")
        assert client.wait(lambda: all(client.channel(t) for t in wanted)), client.channels
        scan_channel = client.channel("/scan")
        assert scan_channel is not None
        assert scan_channel["schemaName"] == "sensor_msgs/msg/LaserScan"
        assert scan_channel["schema"] == registry.msgdef_text("sensor_msgs/msg/LaserScan")
        assert not bridge_endpoints(session, SUBSCRIPTION) - {"/clock"}  # nobody watches yet

        scan, odom = client.subscribe("/scan"), client.subscribe("/odom")
        assert client.wait(
            lambda: len(client.received(scan)) >= 3 and len(client.received(odom)) >= 3
        )
        for _, payload in client.received(scan):
            message = decode(client, "/scan", payload)
            assert len(message.ranges) == scan_samples()
            assert message.header.frame_id == "base_scan"
        for _, payload in client.received(odom):
            message = decode(client, "/odom", payload)
            assert (message.header.frame_id, message.child_frame_id) == ("odom", "base_footprint")
        for topic in (scan, odom):  # log times are the sim's clock (a /clock publisher), in order
            times = [t for t, _ in client.received(topic)]
            assert times == sorted(times)
            assert all(0 <= t < WALL_NS for t in times), times
        assert client.wait(lambda: client.times and client.times[-1] < WALL_NS)  # server time too
        assert set(client.messages) == {"/scan", "/odom"}  # nothing of the others

        watched = bridge_endpoints(session, SUBSCRIPTION)
        assert {"/scan", "/odom"} <= watched
        assert "/joint_states" not in watched  # no traffic for what nobody watches

        # /robot_description was published once, long before: a late subscriber still gets it
        latched = client.subscribe("/robot_description")
        assert client.wait(lambda: bool(client.received(latched)))
        assert "<robot" in decode(client, "/robot_description", client.received(latched)[0][1]).data
        second = FoxgloveClient(port)
        try:
            assert second.wait(lambda: second.channel("/robot_description") is not None)
            again = second.subscribe("/robot_description")
            assert second.wait(lambda: bool(second.received(again)))
        finally:
            second.close()

        client.unsubscribe("/scan")
        assert wait_until(lambda: "/scan" not in bridge_endpoints(session, SUBSCRIPTION), BOUND)
    finally:
        client.close()


@pytest.mark.slow
def test_a_nodes_topic_is_advertised_while_it_runs_and_only_if_it_matches_topics(
    processes: Processes,
) -> None:
    bridge, port = start_bridge(processes, "--topics", "/bridge_.*")
    client = FoxgloveClient(port)
    try:
        assert client.wait(lambda: len(client.times) >= 2)  # no simulator: wall-clock time
        assert all(t > WALL_NS for t in client.times)
        talker = start_node(processes, TALKER)
        assert client.wait(lambda: client.channel("/bridge_test") is not None)
        channel = client.channel("/bridge_test")
        assert channel is not None
        assert channel["schemaName"] == "std_msgs/msg/String"
        client.subscribe("/bridge_test")
        assert client.wait(lambda: len(client.received("/bridge_test")) >= 2)
        log_time, payload = client.received("/bridge_test")[0]
        assert decode(client, "/bridge_test", payload).data == "hello bridge"
        assert log_time > WALL_NS
        topics = {c["topic"] for c in client.channels.values()}
        assert topics == {"/bridge_test"}  # the talker's /rosout and /parameter_events left out

        talker.stop()
        assert client.wait(lambda: channel["id"] in client.unadvertised)
        assert client.channel("/bridge_test") is None
    finally:
        client.close()
    bridge.popen.send_signal(signal.SIGINT)
    _, err = bridge.finish(BOUND)
    assert bridge.returncode == 0, err
    assert "Traceback" not in err
    assert re.search(r"stopped: \d+ messages forwarded on 1 topics", err), err


@pytest.mark.slow
def test_a_client_publishes_cdr_bytes_that_a_rosl_subscriber_reads(
    processes: Processes, session: Any
) -> None:
    from rosbags.typesys import Stores, get_typestore

    listener = start_node(processes, LISTENER)
    _, port = start_bridge(processes)
    client = FoxgloveClient(port)
    try:
        assert "clientPublish" in client.info["capabilities"]
        assert client.info["supportedEncodings"] == ["cdr"]
        client.send("advertise", channels=[{
            "id": 7, "topic": "/from_foxglove", "encoding": "cdr",
            "schemaName": "std_msgs/msg/String",
        }])  # fmt: skip
        store = get_typestore(Stores.ROS2_HUMBLE)
        message = store.types["std_msgs/msg/String"](data="from foxglove")
        frame = (
            b"\x01"
            + struct.pack("<I", 7)
            + bytes(store.serialize_cdr(message, "std_msgs/msg/String"))
        )
        deadline = time.monotonic() + BOUND
        while listener.wait_for("got: from foxglove", timeout=0.2) is None:
            assert time.monotonic() < deadline, listener.text
            client.ws.send(frame)
        assert "/from_foxglove" in bridge_endpoints(session, PUBLISHER)
        assert client.channel("/from_foxglove") is None  # the bridge's own publisher: not echoed
        client.send("unadvertise", channelIds=[7])
        assert wait_until(
            lambda: "/from_foxglove" not in bridge_endpoints(session, PUBLISHER), BOUND
        )
    finally:
        client.close()


@pytest.mark.slow
def test_service_calls_and_parameters_go_through_the_nodes_services(
    processes: Processes, session: Any
) -> None:
    start_node(processes, ADDER)
    _, port = start_bridge(processes)
    client = FoxgloveClient(port)
    try:
        assert client.wait(lambda: "/add_two_ints" in client.services)
        service = client.services["/add_two_ints"]
        assert service["type"] == "example_interfaces/srv/AddTwoInts"
        assert service["request"]["schemaName"] == "example_interfaces/srv/AddTwoInts_Request"
        request, response = service["request"], service["response"]
        assert (request["encoding"], request["schemaEncoding"]) == ("cdr", "ros2msg")
        requests, request_name = typestore_from(request["schemaName"], request["schema"])
        responses, response_name = typestore_from(response["schemaName"], response["schema"])

        def add(a: int, b: int) -> int:
            message = requests.types[request_name](a=a, b=b)
            call = client.call(
                "/add_two_ints", bytes(requests.serialize_cdr(message, request_name))
            )
            assert client.wait(lambda: call in client.responses), client.replies
            answer = responses.deserialize_cdr(client.responses[call], response_name)
            return int(answer.sum)

        assert add(2, 5) == 10  # 2 + 5 + offset 3

        def values(request_id: str) -> list[dict[str, Any]]:
            found = [r for r in client.replies if r.get("id") == request_id]
            return found[0]["parameters"] if found else []

        client.send("getParameters", parameterNames=["/adder.offset"], id="get")
        assert client.wait(lambda: bool(values("get")))
        assert values("get") == [{"name": "/adder.offset", "value": 3}]
        client.send("getParameters", parameterNames=[], id="all")
        assert client.wait(lambda: bool(values("all")))
        assert {"name": "/adder.offset", "value": 3} in values("all")

        client.send("setParameters", parameters=[{"name": "/adder.offset", "value": 40}], id="set")
        assert client.wait(lambda: bool(values("set")))
        assert values("set") == [{"name": "/adder.offset", "value": 40}]
        assert add(2, 5) == 47

        # a change made elsewhere reaches a client that subscribed to the parameter
        client.send("subscribeParameterUpdates", parameterNames=["/adder.offset"])
        assert wait_until(lambda: "/parameter_events" in bridge_endpoints(session, SUBSCRIPTION))
        setter = processes.rosl("param", "set", "/adder", "offset", "7")
        assert setter.wait(timeout=BOUND) == 0
        update = {"op": "parameterValues", "parameters": [{"name": "/adder.offset", "value": 7}]}
        assert client.wait(lambda: update in client.replies), client.replies
    finally:
        client.close()


def test_bad_options_give_one_line_and_a_failure_exit(processes: Processes) -> None:
    taken = socket.socket()
    taken.bind(("127.0.0.1", 0))
    taken.listen()
    try:
        port = str(taken.getsockname()[1])
        cases = {
            ("--port", port): f"port {port} is in use",
            ("--topics", "/scan("): "no regular expression",
            ("--address", "not-an-address"): "is not an IP address",
        }
        for args, words in cases.items():
            child = processes.rosl("bridge", "foxglove", *args)
            out, err = child.communicate(timeout=BOUND)
            assert child.returncode == 1, (args, out, err)
            assert words in err, (args, err)
            assert len(err.strip().splitlines()) == 1, err
            assert "Traceback" not in err
    finally:
        taken.close()


@pytest.mark.parametrize("transport", ["multicast", "inprocess"])
def test_the_bridge_needs_only_the_transport_seam(
    transport: str, domain_id: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    from std_msgs.msg import String

    from rosl.bus.header import topic_hash
    from rosl.executor import SingleThreadedExecutor
    from rosl.introspection.foxglove_bridge import BridgeOptions, FoxgloveBridge
    from rosl.node.context import Context
    from rosl.node.node import Node

    monkeypatch.setenv("ROSL_TRANSPORT", transport)
    context = Context()
    context.init([], domain_id=domain_id)
    bridge = FoxgloveBridge(BridgeOptions(port=0, domain=domain_id))
    thread = threading.Thread(target=bridge.run, args=(lambda: False,), daemon=True)
    client: FoxgloveClient | None = None
    try:
        node = Node("seam_node", context=context)
        publisher = node.create_publisher(String, "/seam_out", 10)
        heard: list[str] = []
        node.create_subscription(String, "/seam_in", lambda m: heard.append(m.data), 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        port = int(bridge.start().rsplit(":", 1)[1])
        thread.start()
        client = FoxgloveClient(port)
        assert client.wait(lambda: client.channel("/seam_out") is not None)
        seam_out = client.subscribe("/seam_out")
        assert client.wait(
            lambda: (publisher.publish(String(data="out")), bool(client.received(seam_out)))[1]
        )
        assert decode(client, "/seam_out", client.received(seam_out)[0][1]).data == "out"
        assert bridge.participant is not None
        wanted = bridge.participant.reader.wanted
        assert topic_hash("/seam_out") in wanted
        client.unsubscribe("/seam_out")
        assert wait_until(lambda: topic_hash("/seam_out") not in wanted, BOUND)  # nobody watches
        client.send("advertise", channels=[{
            "id": 1, "topic": "/seam_in", "encoding": "cdr", "schemaName": "std_msgs/msg/String",
        }])  # fmt: skip
        data = String(data="in")
        from rosl.idl import registry

        frame = b"\x01" + struct.pack("<I", 1) + registry.store().serialize(data)
        assert wait_until(
            lambda: (client.ws.send(frame), executor.spin_once(timeout_sec=0.05), heard)[2],
            BOUND,
        )
        assert heard[0] == "in"
    finally:
        if client is not None:
            client.close()
        bridge.stop()
        thread.join(BOUND)
        bridge.close()
        context.try_shutdown()


def test_the_cli_lists_the_bridge_command() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "rosl", "bridge", "foxglove", "--help"],
        capture_output=True, text=True, timeout=BOUND, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "--topics" in done.stdout
    assert "--address" in done.stdout
