"""The everyday workflow over Zenoh: parameters, bag play and the lock-stepped simulator.

Each test has its own router (tests/zenoh/conftest.py) and domain; every rosl process of the
test, this one included, is on ``ROSL_TRANSPORT=zenoh``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from tests.bag.conftest import Listener
from tests.conftest import REPO, ChildOutput, Processes
from tests.zenoh.conftest import Router, wait_output

if TYPE_CHECKING:
    from pathlib import Path

NS = 1_000_000_000
NODE = (
    "import rosl; rosl.init(); node = rosl.create_node('tuned'); "
    "node.declare_parameter('gain', 2); node.declare_parameter('label', 'left'); "
    "print('ready', flush=True); rosl.spin(node)"
)


def _run(processes: Processes, *args: str) -> str:
    child = processes.rosl(*args)
    out, err = child.communicate(timeout=60)
    assert child.returncode == 0, (args, out, err)
    return out


def test_param_list_get_and_set_reach_a_node_over_zenoh(
    router: Router, processes: Processes, domain_id: int
) -> None:
    node = ChildOutput(processes.python(NODE))
    assert wait_output(node, "ready"), node.text
    listed = _run(processes, "param", "list", "/tuned").split()
    assert {"gain", "label", "use_sim_time"} <= set(listed), listed
    assert _run(processes, "param", "get", "/tuned", "gain").strip() == "Integer value is: 2"
    assert "Set parameter successful" in _run(processes, "param", "set", "/tuned", "gain", "7")
    assert _run(processes, "param", "get", "/tuned", "gain").strip() == "Integer value is: 7"


def _write_bag(folder: Path) -> None:
    """Three /played messages 0.2 s apart (and a last a minute later), a latched /map_name."""
    from mcap.writer import Writer

    from rosl.idl.registry import get_message_class, store

    string = get_message_class("std_msgs/msg/String")
    offered = "- {history: keep_last, depth: %d, reliability: reliable, durability: %s}\n"
    folder.mkdir()
    with (folder / "played_0.mcap").open("wb") as handle:
        writer = Writer(handle)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema("std_msgs/msg/String", "ros2msg", b"string data\n")
        played = writer.register_channel(
            "/played", "cdr", schema, {"offered_qos_profiles": offered % (10, "volatile")}
        )
        latched = writer.register_channel(
            "/map_name", "cdr", schema, {"offered_qos_profiles": offered % (1, "transient_local")}
        )
        writer.add_message(latched, 0, store().serialize(string(data="the map")), 0)
        for index in range(3):
            data = store().serialize(string(data=f"played {index}"))
            writer.add_message(played, (index + 1) * NS // 5, data, (index + 1) * NS // 5)
        # the player runs (and serves its latched topic) until this one, 60 s later
        writer.add_message(played, 60 * NS, store().serialize(string(data="the end")), 60 * NS)
        writer.finish()


def test_bag_play_sends_a_bag_over_zenoh_and_keeps_its_latched_topic(
    router: Router, processes: Processes, domain_id: int, tmp_path: Path, ros: Any
) -> None:
    from rosl.idl.registry import get_message_class, store
    from rosl.node.qos import DurabilityPolicy, QoSProfile

    bag = tmp_path / "played"
    _write_bag(bag)
    listener = Listener(ros, {"/played": "std_msgs/msg/String"})
    player = processes.rosl("bag", "play", str(bag))
    assert listener.spin_until(lambda: len(listener.on("/played")) == 3, timeout=60)
    heard = [store().deserialize(data, "std_msgs/msg/String").data
             for data, _ in listener.on("/played")[:3]]  # fmt: skip
    assert heard == ["played 0", "played 1", "played 2"]
    late: list[str] = []
    listener.node.create_subscription(
        get_message_class("std_msgs/msg/String"), "/map_name", lambda m: late.append(m.data),
        QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL),
    )  # fmt: skip
    assert listener.spin_until(lambda: late == ["the map"], timeout=30), late
    processes.stop(player)


def _demo_bag(processes: Processes, folder: Path) -> tuple[dict[str, list[bytes]], str]:
    from mcap.reader import make_reader

    folder.mkdir()
    child = processes.rosl(
        "launch", "rosl_sim", "demo.launch.py", "duration:=3", "bag:=demo", cwd=folder,
        env={"NO_COLOR": "1", "ROSL_PACKAGE_PATH": str(REPO / "examples")},
    )  # fmt: skip
    out, err = child.communicate(timeout=180)
    assert child.returncode == 0, out[-3000:] + err[-3000:]
    by_topic: dict[str, list[bytes]] = {}
    (mcap,) = (folder / "demo").glob("*.mcap")
    with mcap.open("rb") as handle:
        for _, channel, message in make_reader(handle).iter_messages():
            by_topic.setdefault(channel.topic, []).append(message.data)
    return by_topic, out + err


def test_two_lock_step_runs_over_zenoh_record_the_same_messages(
    router: Router, processes: Processes, domain_id: int, tmp_path: Path
) -> None:
    first, report = _demo_bag(processes, tmp_path / "first")
    assert "lock-step" in report
    assert "went on without" not in report, report[-3000:]  # no controller left behind
    assert "waited" not in report, report[-3000:]
    assert {"/scan", "/odom", "/tf", "/clock", "/cmd_vel"} <= set(first), set(first)
    second, _ = _demo_bag(processes, tmp_path / "second")
    # the controller's replies land in the same step in both runs: the same commands, the
    # same scans, the same end (the in-process recorder's own Zenoh session may miss the
    # simulator's first milliseconds while its subscription propagates: not compared)
    assert first["/cmd_vel"] == second["/cmd_vel"]
    assert first["/scan"][-10:] == second["/scan"][-10:]
    assert first["/odom"][-1] == second["/odom"][-1]
