"""Zenoh settings as rmw_zenoh users give them: config files, overrides, domains.

(User/password and TLS: test_auth.py.)

Every router listens on a free loopback port; every session connects to it only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from tests.conftest import ChildOutput, Processes
from tests.zenoh.conftest import wait_output

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


def test_zenohs_shared_memory_is_off_as_in_rmw_zenoh(monkeypatch) -> None:
    # rmw_zenoh's DEFAULT_RMW_ZENOH_SESSION_CONFIG.json5 has transport/shared_memory/enabled
    # false; zenoh's own default (true) maps a pool in /dev/shm that a killed process leaves
    from rosl.bus.zenoh_config import router_config, session_config

    monkeypatch.delenv("ZENOH_SESSION_CONFIG_URI", raising=False)
    monkeypatch.delenv("ZENOH_ROUTER_CONFIG_URI", raising=False)
    monkeypatch.delenv("ZENOH_CONFIG_OVERRIDE", raising=False)
    assert session_config().get_json("transport/shared_memory/enabled") == "false"
    assert router_config().get_json("transport/shared_memory/enabled") == "false"
    monkeypatch.setenv("ZENOH_CONFIG_OVERRIDE", "transport/shared_memory/enabled=true")
    assert session_config().get_json("transport/shared_memory/enabled") == "true"
