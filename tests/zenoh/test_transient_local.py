"""Transient local on Zenoh: publication caches and history queries as rmw_zenoh makes them.

A publisher with depth 3 sends five messages before anyone listens; a late transient-local
subscriber must get exactly the last three, once each — between rosl processes, from the
plain-zenoh peer's ``AdvancedPublisher`` to rosl, and from rosl to the peer's
``AdvancedSubscriber`` (tests/zenoh/peer.py, no rosl import).
"""

from __future__ import annotations

from typing import Any

from tests.conftest import ChildOutput, Processes, wait_until
from tests.zenoh.conftest import Router, wait_output

LAST_THREE = ["Latched: 3", "Latched: 4", "Latched: 5"]


def _latched_profile() -> Any:
    from rclpy.qos import DurabilityPolicy, QoSProfile

    return QoSProfile(depth=3, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def _publish_five(node: Any) -> Any:
    from std_msgs.msg import String

    publisher = node.create_publisher(String, "/latched", _latched_profile())
    for number in range(1, 6):
        publisher.publish(String(data=f"Latched: {number}"))
    return publisher


def _late_subscription(node: Any, heard: list[str]) -> Any:
    from std_msgs.msg import String

    return node.create_subscription(
        String, "/latched", lambda m: heard.append(m.data), _latched_profile()
    )


def _spin_until(nodes: list[Any], done: Any, timeout: float = 30.0) -> bool:
    import rosl

    def spun() -> bool:
        for node in nodes:
            rosl.spin_once(node, timeout_sec=0.05)
        return bool(done())

    return wait_until(spun, timeout)


def _settle(nodes: list[Any]) -> None:
    """Spin a little more: a duplicate or a sixth message would arrive by now."""
    _spin_until(nodes, lambda: False, timeout=1.5)


def test_a_late_rosl_subscriber_gets_the_last_depth_messages_of_a_rosl_publisher(
    router: Router, processes: Processes, domain_id: int, ros: object
) -> None:
    import rosl

    talker = rosl.create_node("latched_talker")
    _publish_five(talker)
    echo = processes.rosl("topic", "echo", "/latched", "std_msgs/msg/String",
                          "--qos-durability", "transient_local", "--qos-depth", "3")  # fmt: skip
    output = ChildOutput(echo)

    def echoed() -> bool:
        output.pump()
        return "Latched: 5" in output.text["out"]

    assert _spin_until([talker], echoed, 60), output.text
    # and a late subscription of a second node in the publisher's own process
    listener = rosl.create_node("late_listener")
    heard: list[str] = []
    _late_subscription(listener, heard)
    assert _spin_until([talker, listener], lambda: len(heard) >= 3), heard
    _settle([talker, listener])
    output.pump()
    Processes.stop(echo)
    assert heard == LAST_THREE
    echoed_data = [line for line in output.text["out"].splitlines() if line.startswith("data:")]
    assert echoed_data == [f"data: '{text}'" for text in LAST_THREE], output.text


def test_rosl_topic_echo_prints_a_latched_topic_of_the_peer(
    router: Router, processes: Processes, domain_id: int
) -> None:
    router.peer(processes, "latched_talker", domain_id)
    echo = processes.rosl("topic", "echo", "/latched")  # QoS adapted to the publisher's
    output = ChildOutput(echo)
    assert wait_output(output, "Latched: 5", 60), output.text
    _read_for(output, 1.5)  # a duplicate would be printed by now
    Processes.stop(echo)
    echoed = [line for line in output.text["out"].splitlines() if line.startswith("data:")]
    assert echoed == [f"data: '{text}'" for text in LAST_THREE], output.text


def test_a_late_rosl_subscription_gets_the_peer_publishers_cache(
    router: Router, processes: Processes, domain_id: int, ros: object
) -> None:
    import rosl

    router.peer(processes, "latched_talker", domain_id)
    node = rosl.create_node("late_listener")
    heard: list[str] = []
    _late_subscription(node, heard)
    assert _spin_until([node], lambda: len(heard) >= 3), heard
    _settle([node])
    assert heard == LAST_THREE


def test_the_peer_late_subscriber_gets_a_rosl_publishers_cache(
    router: Router, processes: Processes, domain_id: int, ros: object
) -> None:
    import rosl

    talker = rosl.create_node("latched_talker")
    _publish_five(talker)
    child = processes.start(
        [__import__("sys").executable, _peer(), "latched_listener", str(router.port),
         str(domain_id)]
    )  # fmt: skip
    output = ChildOutput(child)

    def heard_all() -> bool:
        output.pump()
        return "'Latched: 5'" in output.text["out"]

    assert _spin_until([talker], heard_all, 60), output.text
    _spin_until([talker], lambda: False, timeout=1.5)
    output.pump()
    heard = [line for line in output.text["out"].splitlines() if line.startswith("heard")]
    assert heard == [f"heard {text!r}" for text in LAST_THREE], output.text


def _read_for(output: ChildOutput, seconds: float) -> None:
    def read() -> bool:
        output.pump()
        return False

    wait_until(read, seconds)


def _peer() -> str:
    from tests.zenoh.conftest import PEER

    return PEER


def test_a_destroyed_publishers_cache_goes_with_it(
    router: Router, processes: Processes, domain_id: int, ros: object
) -> None:
    import rosl

    talker = rosl.create_node("latched_talker")
    talker.destroy_publisher(_publish_five(talker))
    listener = rosl.create_node("late_listener")
    heard: list[str] = []
    _late_subscription(listener, heard)
    _settle([talker, listener])
    assert heard == []  # no history of a publisher that is gone
    # while the subscription does hear a publisher made afterwards (keeping its last three)
    _publish_five(talker)
    assert _spin_until([talker, listener], lambda: len(heard) >= 3), heard
    _settle([talker, listener])
    assert heard == LAST_THREE
