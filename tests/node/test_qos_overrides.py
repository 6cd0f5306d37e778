"""QoS overrides (rclpy.qos_overriding_options) from parameters files and --ros-args."""

from __future__ import annotations

import subprocess
import sys

from tests.node.qos_programs import OVERRIDDEN, RUN_AS_RCLPY, write

BOUND = 30.0

PARAMS = """\
/overridden:
  ros__parameters:
    qos_overrides:
      /qos_chatter:
        publisher:
          reliability: best_effort
          depth: 3
        subscription:
          history: keep_all
"""


def _rosl(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rosl", *args],
        capture_output=True, text=True, timeout=BOUND, check=False,
    )  # fmt: skip


def test_overrides_from_a_parameters_file_change_the_profiles_and_are_read_only(spawn, tmp_path):
    params = tmp_path / "qos.yaml"
    params.write_text(PARAMS)
    child = spawn(
        RUN_AS_RCLPY, write(tmp_path, OVERRIDDEN, "overridden"), "--ros-args", "--params-file", str(params), "--", '{"name": "overridden"}',
    )  # fmt: skip

    child.expect(
        "^publisher history=KEEP_LAST depth=3 reliability=BEST_EFFORT durability=VOLATILE ",
        timeout=BOUND,
    )
    child.expect("^subscription history=KEEP_ALL depth=10 reliability=RELIABLE ", timeout=BOUND)
    child.expect("^ready$", timeout=BOUND)

    got = _rosl("param", "get", "/overridden", "qos_overrides./qos_chatter.publisher.reliability")
    assert got.stdout.strip() == "String value is: best_effort", got.stderr
    listed = _rosl("param", "list", "/overridden").stdout
    assert "  qos_overrides./qos_chatter.subscription.depth" in listed
    assert "qos_overrides./qos_chatter.subscription.lifespan" not in listed  # publishers only
    refused = _rosl(
        "param", "set", "/overridden", "qos_overrides./qos_chatter.publisher.depth", "5"
    )
    assert "read-only" in refused.stdout + refused.stderr


def test_overrides_from_the_command_line_with_an_entity_id_and_chosen_policies(spawn, tmp_path):
    child = spawn(
        RUN_AS_RCLPY, write(tmp_path, OVERRIDDEN, "overridden"), "--ros-args",
        "-p", "qos_overrides./qos_chatter.publisher_fast.deadline:=250000000",
        "-p", "qos_overrides./qos_chatter.publisher.deadline:=999",  # another entity's
        "--", '{"name": "overridden", "entity_id": "fast", "kinds": ["DEADLINE", "DURABILITY"]}',
    )  # fmt: skip

    child.expect("^publisher .* durability=VOLATILE deadline=250000000$", timeout=BOUND)
    child.expect("^subscription .* deadline=0$", timeout=BOUND)


def test_a_bad_override_or_a_refused_profile_names_the_parameter(spawn, tmp_path):
    script, run = write(tmp_path, OVERRIDDEN, "overridden"), RUN_AS_RCLPY

    bad = spawn(run, script, "--ros-args", "-p",
                "qos_overrides./qos_chatter.publisher.reliability:=sometimes",
                "--", '{"name": "overridden"}')  # fmt: skip
    _, err = bad.finish(timeout=BOUND)
    assert bad.returncode != 0
    assert (
        err.strip()
        .splitlines()[-1]
        .endswith(
            "parameter 'qos_overrides./qos_chatter.publisher.reliability': 'sometimes' is no "
            "reliability policy (choose one of system_default, reliable, best_effort, "
            "best_available)"
        )
    )

    for settings, reason in (
        ('{"name": "overridden"}', ": expected a depth of at most 100"),
        ('{"name": "overridden", "bool_callback": true}', ""),
    ):
        deep = spawn(run, script, "--ros-args", "-p",
                     "qos_overrides./qos_chatter.publisher.depth:=5000", "--", settings)  # fmt: skip
        _, err = deep.finish(timeout=BOUND)
        assert deep.returncode != 0
        assert (
            err.strip()
            .splitlines()[-1]
            .endswith(
                "Provided QoS overrides for publisher `/qos_chatter` with id `None`, are not valid"
                + reason
            )
        )
