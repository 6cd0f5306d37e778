"""rosl on Zenoh against an rmw_zenoh node written with the plain zenoh API (peer.py).

Every test has its own router on a free loopback port and its own domain; the peer knows
nothing of rosl: it speaks the key expressions, tokens and attachments of docs/design.md.
"""

from __future__ import annotations

import re

from tests.conftest import ChildOutput, Processes, wait_until
from tests.zenoh.conftest import Router, wait_output


def test_a_rosl_node_hears_the_peer_talker_and_the_peer_hears_rosl(
    router: Router, processes: Processes, domain_id: int, ros: object
) -> None:
    from std_msgs.msg import String

    import rosl

    router.peer(processes, "talker", domain_id)
    listener = router.peer(processes, "listener", domain_id)
    node = rosl.create_node("rosl_node")
    heard: list[str] = []
    node.create_subscription(String, "/chatter", lambda m: heard.append(m.data), 10)
    publisher = node.create_publisher(String, "/chatter", 10)

    def exchanged() -> bool:
        publisher.publish(String(data="from rosl"))
        rosl.spin_once(node, timeout_sec=0.1)
        listener.pump()
        return any(h.startswith("Hello World") for h in heard) and (
            "'from rosl'" in listener.text["out"]
        )

    assert wait_until(exchanged, 30), (heard[-3:], listener.text)
    # rosl's attachment as rmw_zenoh reads it: 33 bytes, a 16-byte GID
    assert re.search(r"heard 'from rosl' seq=\d+ gidlen=16 size=33", listener.text["out"])


def _echo_and_list_chatter(processes: Processes) -> None:
    """``rosl topic echo --once`` prints the peer talker's message; ``topic list`` shows it."""
    echo = processes.rosl("topic", "echo", "/chatter", "--once")
    out, err = echo.communicate(timeout=60)
    assert echo.returncode == 0, err
    assert "data: 'Hello World: " in out
    listing = processes.rosl("topic", "list", "-t")
    out, err = listing.communicate(timeout=60)
    assert "/chatter [std_msgs/msg/String]" in out, (out, err)


def test_rosl_cli_echo_list_and_node_list_see_the_peer(
    router: Router, processes: Processes, domain_id: int
) -> None:
    router.peer(processes, "talker", domain_id)
    _echo_and_list_chatter(processes)
    nodes = processes.rosl("node", "list")
    out, err = nodes.communicate(timeout=60)
    assert "/talker" in out.split(), (out, err)


def test_rosl_topic_pub_reaches_the_peer_listener(
    router: Router, processes: Processes, domain_id: int
) -> None:
    listener = router.peer(processes, "listener", domain_id)
    pub = processes.rosl("topic", "pub", "-r", "5", "/chatter", "std_msgs/msg/String",
                         "{data: hi there}")  # fmt: skip
    assert wait_output(listener, "'hi there'", 60), listener.text
    Processes.stop(pub)


def test_rosl_service_call_is_answered_by_the_peer_server(
    router: Router, processes: Processes, domain_id: int
) -> None:
    server = router.peer(processes, "server", domain_id)
    call = processes.rosl("service", "call", "/add_two_ints",
                          "example_interfaces/srv/AddTwoInts", "{a: 2, b: 40}")  # fmt: skip
    out, err = call.communicate(timeout=60)
    assert call.returncode == 0, err
    assert "sum=42" in out
    server.pump()
    assert "served 2+40" in server.text["out"]


def test_the_peer_client_is_answered_by_a_rosl_server(
    router: Router, processes: Processes, domain_id: int, ros: object
) -> None:
    from example_interfaces.srv import AddTwoInts

    import rosl

    node = rosl.create_node("add_two_ints_server")

    def add(request: AddTwoInts.Request, response: AddTwoInts.Response) -> AddTwoInts.Response:
        response.sum = request.a + request.b
        return response

    node.create_service(AddTwoInts, "/add_two_ints", add)
    client = processes.start([__import__("sys").executable, router_peer_path(), "client",
                              str(router.port), str(domain_id), "20", "22"])  # fmt: skip
    output = ChildOutput(client)

    def answered() -> bool:
        rosl.spin_once(node, timeout_sec=0.1)
        output.pump()
        return "sum " in output.text["out"]

    assert wait_until(answered, 60), output.text
    assert re.search(r"sum 42 seq=\d+ mine=True", output.text["out"])


def test_the_peer_sees_rosl_liveliness_tokens(
    router: Router, processes: Processes, domain_id: int, ros: object
) -> None:
    import zenoh
    from std_msgs.msg import String

    import rosl

    node = rosl.create_node("talker", namespace="/robot1")
    node.create_publisher(String, "chatter", 7)
    config = zenoh.Config()
    config.insert_json5("connect/endpoints", f'["{router.endpoint}"]')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("transport/shared_memory/enabled", "false")  # rmw_zenoh's default
    with zenoh.open(config) as session:

        def tokens() -> list[str]:
            return [
                str(r.ok.key_expr)
                for r in session.liveliness().get(f"@ros2_lv/{domain_id}/**", timeout=2.0)
                if r.ok is not None
            ]

        found: list[str] = []

        def published() -> bool:  # (what the query that saw it got: a later one may time out)
            found[:] = tokens()
            return any("/MP/%/%robot1/talker/%robot1%chatter/" in t for t in found)

        assert wait_until(published, 30), found
    assert any(re.fullmatch(rf"@ros2_lv/{domain_id}/[0-9a-f]+/(\d+)/\1/NN/%/%robot1/talker", t)
               for t in found), found  # fmt: skip
    assert any(t.endswith(
        "/MP/%/%robot1/talker/%robot1%chatter/std_msgs::msg::dds_::String_/"
        "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18/::,7:,:,:,,"
    ) for t in found), found  # fmt: skip


def router_peer_path() -> str:
    from tests.zenoh.conftest import PEER

    return PEER


def test_a_humble_peer_without_type_hashes_is_heard_by_name_and_type(
    router: Router, processes: Processes, domain_id: int, ros: object
) -> None:
    from std_msgs.msg import String

    import rosl

    router.peer(processes, "humble_talker", domain_id)
    node = rosl.create_node("rosl_listener")
    heard: list[str] = []
    node.create_subscription(String, "/chatter", lambda m: heard.append(m.data), 10)

    def received() -> bool:
        rosl.spin_once(node, timeout_sec=0.1)
        return any(h.startswith("Hello World") for h in heard)

    assert wait_until(received, 30), heard
    _echo_and_list_chatter(processes)


def test_a_gap_in_the_peers_sequence_numbers_is_counted_lost_and_a_duplicate_dropped(
    router: Router, processes: Processes, domain_id: int, ros: object
) -> None:
    from std_msgs.msg import String

    import rosl

    node = rosl.create_node("rosl_listener")
    heard: list[str] = []
    subscription = node.create_subscription(String, "/chatter", lambda m: heard.append(m.data), 10)
    router.peer(processes, "gappy_talker", domain_id)

    def received() -> bool:
        rosl.spin_once(node, timeout_sec=0.1)
        return "m7" in heard

    assert wait_until(received, 30), heard

    def spun() -> bool:
        rosl.spin_once(node, timeout_sec=0.1)
        return False

    wait_until(spun, 1.0)  # a second m7 would be taken by now
    assert heard == ["m1", "m2", "m3", "m6", "m7"]
    assert subscription.lost == 2
