"""Two hosts: network namespaces joined by a veth pair, a router and a talker in one, then
``rosl topic echo`` and a recorder in the other, all over Zenoh.

The second test does the same with user/password and TLS on every link (files made by the
test, see tests/zenoh/secure.py).

Needs ``ip netns`` (root, or CAP_NET_ADMIN), else skips with the reason. Everything stays in
the namespaces the test makes and deletes; the second namespace's loopback stays down, so
its traffic can only cross the veth.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING

from rosbags.rosbag2 import Reader

from tests.bus.test_interface_netns import Namespaces, ip, netns, stop, veth_pair
from tests.conftest import ChildOutput, wait_until
from tests.zenoh.conftest import wait_output
from tests.zenoh.secure import Secured, make_tls

if TYPE_CHECKING:
    from pathlib import Path

__all__ = ["netns"]
TOPIC = "/netns_zenoh"


def _env(router: str, own: str, domain: int) -> dict[str, str]:
    return {
        "ROSL_TRANSPORT": "zenoh",
        "ROSL_DOMAIN_ID": str(domain),
        "ZENOH_CONFIG_OVERRIDE": (
            f'connect/endpoints=["tcp/{router}:7447"];listen/endpoints=["tcp/{own}:0"]'
        ),
    }


def test_a_talker_on_one_host_is_echoed_and_recorded_on_the_other(
    netns: Namespaces, domain_id: int, tmp_path: Path
) -> None:
    a, _, b, _ = veth_pair(netns)
    subnet = int(netns.suffix[:2], 16) % 250 + 1
    ip("-n", a, "link", "set", "lo", "up")  # the router's host reaches its own address
    host_a, host_b = f"10.77.{subnet}.1", f"10.77.{subnet}.2"
    rosl = [sys.executable, "-m", "rosl"]
    router = ChildOutput(
        netns.run(
            a,
            [*rosl, "zenoh", "router", "--listen", f"tcp/{host_a}:7447"],
            env={"ZENOH_CONFIG_OVERRIDE": ""},
        )
    )
    assert wait_output(router, "listening on"), router.text
    talker = netns.run(
        a,
        [
            *rosl,
            "topic",
            "pub",
            "-r",
            "10",
            TOPIC,
            "std_msgs/msg/String",
            "{data: across the veth}",
        ],
        env=_env(host_a, host_a, domain_id),
    )
    talking = ChildOutput(talker)
    assert wait_output(talking, "publishing #2"), talking.text  # its discovery is done by then
    bag = tmp_path / "across"
    recorder = netns.run(
        b, [*rosl, "bag", "record", TOPIC, "-o", str(bag)], env=_env(host_a, host_b, domain_id)
    )
    echo = netns.run(
        b, [*rosl, "topic", "echo", TOPIC, "--once"], env=_env(host_a, host_b, domain_id)
    )
    out, err = echo.communicate(timeout=90)
    assert echo.returncode == 0, err
    assert "data: across the veth" in out

    def recorded() -> bool:
        return recorder.poll() is None and bag.exists()

    assert wait_until(recorded, 30)
    wait_until(lambda: False, 3.0)  # let the recorder take a few more messages
    stop(recorder)
    stop(talker)
    with Reader(bag) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
    assert counts.get(TOPIC, 0) > 0, counts


def test_user_password_and_tls_carry_a_talker_across_the_veth(
    netns: Namespaces, domain_id: int, tmp_path: Path
) -> None:
    a, _, b, _ = veth_pair(netns)
    subnet = int(netns.suffix[:2], 16) % 250 + 1
    ip("-n", a, "link", "set", "lo", "up")
    host_a, host_b = f"10.77.{subnet}.1", f"10.77.{subnet}.2"
    secured = Secured(tmp_path, f"tls/{host_a}:7447", make_tls(tmp_path, [host_a, host_b]))
    rosl = [sys.executable, "-m", "rosl"]
    router_file = secured.router_file()
    router = ChildOutput(netns.run(
        a, [*rosl, "zenoh", "router"],
        env={"ZENOH_ROUTER_CONFIG_URI": str(router_file), "ZENOH_CONFIG_OVERRIDE": ""},
    ))  # fmt: skip
    assert wait_output(router, "listening on"), router.text
    env_a = {**secured.session_env(f"tls/{host_a}:0"), "ROSL_DOMAIN_ID": str(domain_id)}
    env_b = {**secured.session_env(f"tls/{host_b}:0"), "ROSL_DOMAIN_ID": str(domain_id)}
    talker = netns.run(
        a, [*rosl, "topic", "pub", "-r", "10", TOPIC, "std_msgs/msg/String", "{data: sealed}"],
        env=env_a,
    )  # fmt: skip
    talking = ChildOutput(talker)
    assert wait_output(talking, "publishing #2"), talking.text
    echo = netns.run(b, [*rosl, "topic", "echo", TOPIC, "--once"], env=env_b)
    out, err = echo.communicate(timeout=90)
    assert echo.returncode == 0, err
    assert "data: sealed" in out
    stop(talker)
