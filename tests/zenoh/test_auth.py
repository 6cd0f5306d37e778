"""Zenoh with authentication: user/password and TLS from configuration files, as rmw_zenoh's.

Every router listens on a free loopback port and only admits sessions with the right
credentials; data, parameter services and the graph flow between admitted ones, and a
session without them sees nobody. Half a user/password pair is refused in one line.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.conftest import ChildOutput, Processes
from tests.zenoh.conftest import ROUTER_PORT, wait_output
from tests.zenoh.secure import LINKED, Secured, make_tls

if TYPE_CHECKING:
    from pathlib import Path

NODE = (
    "import rosl; rosl.init(); node = rosl.create_node('guarded_node'); "
    "node.declare_parameter('answer', 42); print('ready', flush=True); rosl.spin(node)"
)
LISTEN_TCP, LISTEN_TLS = "tcp/127.0.0.1:0", "tls/127.0.0.1:0"


def _router(processes: Processes, secured: Secured) -> None:
    """Start the router of ``secured`` (on port 0) and point its sessions at its real port."""
    router_file = secured.router_file()
    router = processes.rosl(
        "zenoh", "router",
        env={"ZENOH_ROUTER_CONFIG_URI": str(router_file), "ZENOH_CONFIG_OVERRIDE": ""},
    )  # fmt: skip
    output = ChildOutput(router)
    assert wait_output(output, "listening on"), output.text
    found = ROUTER_PORT.search(output.text["out"])
    assert found, output.text
    secured.router = f"{secured.router.split('/')[0]}/127.0.0.1:{found.group(1)}"


def _exchange(processes: Processes, secured: Secured, listen: str) -> None:
    """A talker, an echo, a node's parameters and the graph, all with the right credentials."""
    env = secured.session_env(listen)
    talker = ChildOutput(processes.rosl(
        "topic", "pub", "-r", "10", "/guarded", "std_msgs/msg/String", "{data: hello}", env=env
    ))  # fmt: skip
    assert wait_output(talker, "publishing #2"), talker.text
    node = ChildOutput(processes.python(NODE, env=env))
    assert wait_output(node, "ready"), node.text
    echo = processes.rosl("topic", "echo", "/guarded", "--once", env=env)
    out, err = echo.communicate(timeout=60)
    assert (echo.returncode, "data: hello" in out) == (0, True), (out, err)
    get = processes.rosl("param", "get", "/guarded_node", "answer", env=env)
    out, err = get.communicate(timeout=60)
    assert (get.returncode, out.strip()) == (0, "Integer value is: 42"), err
    nodes = processes.rosl("node", "list", env=env)
    out, err = nodes.communicate(timeout=60)
    assert "/guarded_node" in out.split(), (out, err)


def test_user_and_password_peers_exchange_data_and_strangers_stay_out(
    processes: Processes, domain_id: int, tmp_path: Path
) -> None:
    secured = Secured(tmp_path, "tcp/127.0.0.1:0")
    _router(processes, secured)
    _exchange(processes, secured, LISTEN_TCP)
    # the router admits the right password only (a refused session sees nobody)
    friend = processes.python(LINKED, env=secured.session_env(LISTEN_TCP))
    stranger = processes.python(LINKED, env=secured.session_env(LISTEN_TCP, "wrong"))
    assert friend.communicate(timeout=60)[0].split() == ["linked"]
    assert stranger.communicate(timeout=60)[0].split() == ["alone"]
    listing = processes.rosl("topic", "list", env=secured.session_env(LISTEN_TCP, "wrong"))
    out, err = listing.communicate(timeout=60)
    assert "/guarded" not in out, (out, err)


def test_tls_with_user_and_password_carries_data_and_a_stranger_ca_stays_out(
    processes: Processes, domain_id: int, tmp_path: Path
) -> None:
    tls = make_tls(tmp_path, ["127.0.0.1"])
    secured = Secured(tmp_path, "tls/127.0.0.1:0", tls)
    _router(processes, secured)
    _exchange(processes, secured, LISTEN_TLS)
    other = tmp_path / "other"
    other.mkdir()
    impostor = Secured(other, secured.router, make_tls(other, ["127.0.0.1"]))
    stranger = processes.python(LINKED, env=impostor.session_env(LISTEN_TLS))
    assert stranger.communicate(timeout=60)[0].split() == ["alone"]


def test_half_a_user_password_pair_is_one_line(processes: Processes, domain_id: int) -> None:
    for override, lack in (('transport/auth/usrpwd/user="robot"', "no password"),
                           ('transport/auth/usrpwd/password="s3cret"', "no user")):  # fmt: skip
        child = processes.rosl(
            "topic", "list", env={"ROSL_TRANSPORT": "zenoh", "ZENOH_CONFIG_OVERRIDE": override}
        )
        _, err = child.communicate(timeout=60)
        assert child.returncode == 1, err
        assert len(err.strip().splitlines()) == 1, err
        have = "user" if lack == "no password" else "password"
        assert f"transport/auth/usrpwd has a {have} but {lack}" in err
        assert "Traceback" not in err


def test_a_missing_dictionary_file_is_one_line_naming_it(
    processes: Processes, domain_id: int, tmp_path: Path
) -> None:
    missing = tmp_path / "nowhere" / "users.txt"
    child = processes.rosl(
        "zenoh", "router", "--listen", "tcp/127.0.0.1:0",
        env={"ZENOH_CONFIG_OVERRIDE": f'transport/auth/usrpwd/dictionary_file="{missing}"'},
    )  # fmt: skip
    _, err = child.communicate(timeout=60)
    assert child.returncode == 1, err
    assert len(err.strip().splitlines()) == 1, err
    assert "Invalid user-password dictionary file" in err
    assert "Traceback" not in err
