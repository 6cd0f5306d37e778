"""Zenoh settings as rmw_zenoh users give them: config files, overrides, domains, user/password.

Every router listens on a free loopback port; every session connects to it only.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from tests.conftest import ChildOutput, Processes
from tests.zenoh.conftest import free_port, wait_output

if TYPE_CHECKING:
    from pathlib import Path

    from tests.zenoh.conftest import Router


def _pub(processes: Processes, topic: str, env: dict[str, str] | None = None) -> ChildOutput:
    child = processes.rosl(
        "topic", "pub", "-r", "10", topic, "std_msgs/msg/String", "{data: hello}", env=env
    )
    output = ChildOutput(child)
    assert wait_output(output, "publishing #2"), output.text
    return output


def test_ros_domain_id_partitions_one_router(
    router: Router, processes: Processes, domain_id: int
) -> None:
    _pub(processes, "/partitioned")
    same = processes.rosl("topic", "echo", "/partitioned", "--once")
    out, err = same.communicate(timeout=60)
    assert (same.returncode, "data: hello" in out) == (0, True), err
    other = processes.rosl(
        "topic", "list", env={"ROSL_DOMAIN_ID": "", "ROS_DOMAIN_ID": str(domain_id + 1)}
    )
    out, err = other.communicate(timeout=60)
    assert other.returncode == 0, err
    assert "/partitioned" not in out


def test_user_and_password_from_config_files_keep_strangers_out(
    processes: Processes, domain_id: int, tmp_path: Path
) -> None:
    port = free_port()
    (tmp_path / "users.txt").write_text("robot:s3cret\n")
    router_file = tmp_path / "router.json5"
    router_file.write_text(json.dumps({
        "mode": "router",
        "listen": {"endpoints": [f"tcp/127.0.0.1:{port}"]},
        "scouting": {"multicast": {"enabled": False}},
        "transport": {"auth": {"usrpwd": {"dictionary_file": str(tmp_path / "users.txt")}}},
    }))  # fmt: skip
    router = processes.rosl(
        "zenoh", "router",
        env={"ZENOH_ROUTER_CONFIG_URI": str(router_file), "ZENOH_CONFIG_OVERRIDE": ""},
    )  # fmt: skip
    assert wait_output(ChildOutput(router), f"the endpoints of {router_file}")

    def session(password: str) -> dict[str, str]:
        path = tmp_path / f"session-{password}.json5"
        path.write_text(json.dumps({
            "mode": "peer",
            "connect": {"endpoints": [f"tcp/127.0.0.1:{port}"]},
            "listen": {"endpoints": ["tcp/127.0.0.1:0"]},
            "scouting": {"multicast": {"enabled": False}},
            "transport": {"auth": {"usrpwd": {  # peers link directly: each checks the other
                "user": "robot", "password": password,
                "dictionary_file": str(tmp_path / "users.txt"),
            }}},
        }))  # fmt: skip
        return {"ROSL_TRANSPORT": "zenoh", "ZENOH_SESSION_CONFIG_URI": str(path),
                "ZENOH_CONFIG_OVERRIDE": ""}  # fmt: skip

    _pub(processes, "/guarded", session("s3cret"))
    # rosl's session takes its credentials from the file: the router admits the right ones
    # (a rosl process that cannot link to the router sees nobody; the session's own view)
    code = (
        "import time; from rosl.bus.zenoh_transport import ZenohTransport; "
        "t = ZenohTransport(0); deadline = time.monotonic() + 20\n"
        "while not t.session.info.routers_zid() and time.monotonic() < deadline:\n"
        "    time.sleep(0.05)\n"
        "print('linked' if t.session.info.routers_zid() else 'alone'); t.close()"
    )
    friend = processes.python(code, env=session("s3cret"))
    stranger = processes.python(code, env=session("wrong"))
    assert friend.communicate(timeout=60)[0].split() == ["linked"]
    assert stranger.communicate(timeout=60)[0].split() == ["alone"]
    listing = processes.rosl("topic", "list", env=session("wrong"))
    out, err = listing.communicate(timeout=60)
    assert "/guarded" not in out, (out, err)


def test_a_bad_override_is_one_line_naming_it(processes: Processes, domain_id: int) -> None:
    child = processes.rosl(
        "topic", "list",
        env={"ROSL_TRANSPORT": "zenoh", "ZENOH_CONFIG_OVERRIDE": "connect/endpoints"},
    )  # fmt: skip
    _, err = child.communicate(timeout=60)
    assert child.returncode == 1
    assert (
        err.strip().splitlines()
        == ["rosl: error: ZENOH_CONFIG_OVERRIDE: 'connect/endpoints' is not key=value"]
        or "ZENOH_CONFIG_OVERRIDE: 'connect/endpoints' is not key=value" in err.splitlines()[-1]
    )
    assert "Traceback" not in err


def test_a_missing_session_config_file_is_one_line_naming_it(
    processes: Processes, domain_id: int, tmp_path: Path
) -> None:
    missing = tmp_path / "nowhere.json5"
    child = processes.rosl(
        "node", "list",
        env={"ROSL_TRANSPORT": "zenoh", "ZENOH_SESSION_CONFIG_URI": str(missing)},
    )  # fmt: skip
    _, err = child.communicate(timeout=60)
    assert child.returncode == 1
    assert f"ZENOH_SESSION_CONFIG_URI={missing}: not a Zenoh configuration" in err
    assert "Traceback" not in err


def test_an_unknown_transport_is_refused_by_the_command_line(processes: Processes) -> None:
    child = processes.rosl("topic", "list", "--transport", "carrier-pigeon")
    _, err = child.communicate(timeout=60)
    assert child.returncode == 2
    assert "carrier-pigeon" in err


def test_a_bad_listen_endpoint_is_one_line(processes: Processes) -> None:
    child = processes.rosl("zenoh", "router", "--listen", "not an endpoint")
    _, err = child.communicate(timeout=60)
    assert child.returncode == 1
    assert len(err.strip().splitlines()) == 1
    assert "--listen: Zenoh refuses" in err
    assert "Endpoints must be of the form" in err
    assert "Json5Err" not in err  # Rust's debug wrapper is taken off
    assert "Traceback" not in err


def test_an_endpoint_zenoh_cannot_open_is_named(processes: Processes) -> None:
    child = processes.rosl("zenoh", "router", "--listen", "tcp/127.0.0.1:99999")
    _, err = child.communicate(timeout=60)
    assert child.returncode == 1
    assert len(err.strip().splitlines()) == 1
    assert "cannot open a Zenoh session" in err
    assert "tcp/127.0.0.1:99999" in err


def test_a_second_router_on_a_taken_port_is_one_line(router: Router, processes: Processes) -> None:
    child = processes.rosl(
        "zenoh", "router", "--listen", router.endpoint, env={"ZENOH_CONFIG_OVERRIDE": ""}
    )
    _, err = child.communicate(timeout=60)
    assert child.returncode == 1
    assert len(err.strip().splitlines()) == 1
    assert "cannot open a Zenoh session" in err
