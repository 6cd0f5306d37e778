"""``rosl doctor``: one line per check, ROS 2's summary, exit 1 on a failed check."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

from tests.cli.conftest import Result
from tests.conftest import write_package
from tests.graph.support import Watched

if TYPE_CHECKING:
    from pathlib import Path

    from tests.conftest import Processes

NODES = """
import sys
import rosl
from std_msgs.msg import Int32, String

rosl.init([])
node = rosl.Node(sys.argv[1])
if len(sys.argv) > 2:
    kind, topic, type_name = sys.argv[2:5]
    msg_type = {"String": String, "Int32": Int32}[type_name]
    if kind == "pub":
        node.create_publisher(msg_type, topic, 10)
    else:
        node.create_subscription(msg_type, topic, lambda m: None, 10)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


def run(processes: Processes, *args: str, cwd: Path | None = None, env=None) -> Result:
    child = processes.rosl("doctor", *args, cwd=cwd, env={"NO_COLOR": "1", **(env or {})})
    out, err = child.communicate(timeout=60)
    return Result(child.returncode, out, err)


def start(processes: Processes, *args: str) -> Watched:
    child = Watched(processes.python(NODES, *args))
    child.wait_ready()
    return child


def check_line(result: Result, name: str) -> str:
    lines = [line for line in result.out.splitlines() if re.match(rf"^\[....\] {name}: ", line)]
    assert len(lines) == 1, result.out
    return lines[0]


def test_doctor_passes_on_a_clean_domain(processes, domain_id: int) -> None:
    result = run(processes)
    assert result.code == 0, result.out + result.err
    assert "Traceback" not in result.err
    for name in ("domain", "network", "security", "package", "interface", "node", "topic"):
        assert check_line(result, name).startswith("[ OK ]")
    assert f"domain {domain_id} (from ROSL_DOMAIN_ID)" in check_line(result, "domain")
    assert result.out.endswith("\nAll 7 checks passed\n\n")


def test_a_publisher_without_subscriber_is_a_warning_not_a_failure(processes) -> None:
    start(processes, "controller", "pub", "/cmd_vel", "String")
    result = run(processes)
    assert result.code == 0, result.out
    assert check_line(result, "topic").startswith("[WARN]")
    assert "UserWarning: Publisher without subscriber detected on /cmd_vel." in result.out
    assert "/rosout" not in result.out  # every node's /rosout is not worth a warning
    assert "All 7 checks passed" in result.out


def test_two_nodes_with_the_same_name_fail_the_node_check(processes) -> None:
    start(processes, "twin")
    start(processes, "twin")
    result = run(processes)
    assert result.code == 1, result.out
    assert check_line(result, "node").startswith("[FAIL]")
    assert "2 nodes are named /twin" in result.out
    assert result.out.endswith("\n1/7 check(s) failed\n\nFailed modules: node\n")


def test_a_topic_with_two_types_fails_the_topic_check(processes) -> None:
    start(processes, "speaker", "pub", "/mixed", "String")
    start(processes, "counter", "sub", "/mixed", "Int32")
    result = run(processes)
    assert result.code == 1, result.out
    assert (
        "topic /mixed has more than one type: std_msgs/msg/Int32, std_msgs/msg/String" in result.out
    )
    assert result.out.rstrip().endswith("Failed modules: topic")


def test_a_broken_package_xml_in_the_workspace_is_reported_with_its_place(
    processes, workspace: Path
) -> None:
    write_package(workspace / "src", "good_pkg")
    write_package(workspace / "src", "bad_pkg", manifest="<package>\n  <name>bad_pkg\n</package>\n")
    result = run(processes, cwd=workspace)
    assert result.code == 1, result.out
    assert check_line(result, "package").startswith("[FAIL] package: 1 broken package.xml; ")
    assert re.search(r"^       src/bad_pkg/package\.xml:\d+:\d+: package\.xml is not well-formed",
                     result.out, re.M), result.out  # fmt: skip
    assert "Failed modules: package" in result.out


def test_a_bad_interface_file_is_reported_with_file_line_and_column(
    processes, workspace: Path
) -> None:
    write_package(workspace / "src", "demo_msgs", {"msg/Bad.msg": "int32 x\nfloat65 y\n"})
    result = run(processes, cwd=workspace)
    assert result.code == 1, result.out
    assert check_line(result, "interface").startswith("[FAIL] interface: 1 of ")
    assert re.search(r"^       src/demo_msgs/msg/Bad\.msg:2:\d+: ", result.out, re.M), result.out
    assert "Failed modules: interface" in result.out


def test_a_broken_network_setting_fails_the_network_check_in_one_line(processes) -> None:
    result = run(processes, env={"ROSL_INTERFACE": "nosuch0"})
    assert result.code == 1
    assert check_line(result, "network") == (
        "[FAIL] network: ROSL_INTERFACE=nosuch0: no such interface with an IPv4 address "
        "(No such device)"
    )
    assert result.out.rstrip().endswith("Failed modules: network")
    assert "Traceback" not in result.err


def test_disagreeing_domain_variables_are_a_warning(processes, domain_id: int) -> None:
    other = str(domain_id + 1 if domain_id < 232 else domain_id - 1)
    result = run(processes, env={"ROS_DOMAIN_ID": other})
    assert result.code == 0, result.out
    assert check_line(result, "domain").startswith("[WARN]")
    assert f"ROSL_DOMAIN_ID={domain_id} and ROS_DOMAIN_ID={other} disagree" in result.out


def test_report_prints_ros2_doctor_sections_with_padded_names(processes, domain_id: int) -> None:
    start(processes, "talker", "pub", "/chatter", "String")
    result = run(processes, "--report")
    assert result.code == 0, result.out
    out = result.out
    for title in (
        "PLATFORM INFORMATION",
        "ROSL INFORMATION",
        "NETWORK CONFIGURATION",
        "TOPIC LIST",
    ):
        assert f"\n   {title}\n" in out
    network = out.split("NETWORK CONFIGURATION\n")[1].split("\n\n")[0].splitlines()
    assert network[0] == "hostname             : " + network[0].split(": ", 1)[1]
    assert f"port                 : {17400 + domain_id}" in network
    assert f"discovery group      : 239.255.{domain_id}.0" in network
    topics = out.split("TOPIC LIST\n")[1].split("\n\n")[0].splitlines()
    at = topics.index("topic               : /chatter")
    assert topics[at + 1 : at + 3] == ["publisher count     : 1", "subscriber count    : 0"]
    assert "All 7 checks passed" in out


READING = """
import sys
import rosl
from defs_pkg.msg import Reading

rosl.init([])
node = rosl.Node(sys.argv[1])
if sys.argv[2] == "pub":
    node.create_publisher(Reading, "/reading", 10)
else:
    node.create_subscription(Reading, "/reading", lambda m: None, 10)
print("ready", flush=True)
rosl.spin(node)
rosl.shutdown()
"""


def test_one_type_read_from_two_different_msg_files_fails_the_topic_check(
    processes, tmp_path: Path
) -> None:
    paths = {}
    for folder, field in (("old", "int64"), ("new", "float64")):
        write_package(tmp_path / folder, "defs_pkg", {"msg/Reading.msg": f"{field} value\n"})
        paths[folder] = {"ROSL_PACKAGE_PATH": str(tmp_path / folder)}
    for name, role, folder in (("old_talker", "pub", "old"), ("new_listener", "sub", "new")):
        Watched(processes.python(READING, name, role, env=paths[folder])).wait_ready()
    result = run(processes)
    assert result.code == 1, result.out
    assert (
        "topic /reading: defs_pkg/msg/Reading has 2 different definitions "
        "(/old_talker; /new_listener)"
        in result.out
        or "topic /reading: defs_pkg/msg/Reading has 2 different definitions "
        "(/new_listener; /old_talker)"
        in result.out
    ), result.out


def test_doctor_says_which_key_signs_and_reports_strangers_in_one_line(
    processes, domain_id: int
) -> None:
    env = {"ROSL_KEY": "doctor's team"}
    stranger = processes.python(NODES, "stranger", env={"ROSL_KEY": "another user"})
    assert stranger.stdout is not None
    assert stranger.stdout.readline().strip() == "ready"
    result = run(processes, env=env)
    line = check_line(result, "security")
    assert line.startswith("[WARN] security: datagrams are signed with the key from ROSL_KEY")
    warnings = [x for x in result.out.splitlines() if "another key" in x]
    assert len(warnings) == 1, result.out
    assert "dropped" in warnings[0]
    assert "/stranger" not in result.out
    assert result.code == 0  # a warning, not a failure


def test_doctor_says_when_authentication_is_off(processes, domain_id: int) -> None:
    result = run(processes, env={"ROSL_KEY": "none"})
    line = check_line(result, "security")
    assert line == "[WARN] security: authentication is off (ROSL_KEY=none)"
    assert "any process on this host can publish" in result.out


def test_doctor_passes_security_when_only_our_key_is_heard(processes, domain_id: int) -> None:
    start(processes, "friend")
    result = run(processes)
    line = check_line(result, "security")
    assert line.startswith("[ OK ] security: datagrams are signed with the key from ")
