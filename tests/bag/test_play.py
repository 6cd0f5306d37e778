"""``rosl bag play``: recorded bytes back on the bus, in order, with the recorded timing."""

from __future__ import annotations

import shutil
import signal
import time
from typing import TYPE_CHECKING

import pytest

from tests.bag.conftest import TYPES, Listener, mcap_messages, torn_bag
from tests.conftest import ChildOutput

if TYPE_CHECKING:
    import subprocess
    from pathlib import Path

NS = 1_000_000_000


def _play(processes, bag: Path, *args: str) -> subprocess.Popen[str]:
    return processes.rosl("bag", "play", str(bag), *args)


def _gap(stamps: list[int], first: int, second: int) -> float:
    return (stamps[second] - stamps[first]) / NS


def test_play_sends_the_recorded_bytes_in_order_with_the_recorded_gaps(
    ros, processes, scenario_bag
):
    recorded = [m for m in mcap_messages(scenario_bag) if m.topic in TYPES]
    listener = Listener(ros, TYPES)
    player = _play(processes, scenario_bag)
    listener.spin_while_running(player)
    out, err = player.communicate(timeout=15)
    assert player.returncode == 0, err
    # each topic has its own socket: the send times give the order across topics
    by_send_time = sorted(listener.heard, key=lambda h: h[2])
    heard = [(topic, data) for topic, data, _ in by_send_time]
    assert heard == [(m.topic, m.data) for m in recorded]
    assert "played 12 messages" in out
    assert "/chatter 5" in out
    # the recording holds the scenario's two pauses (it sends m4 1.2 s after m0)
    assert _gap([m.log_time for m in recorded], 0, -1) >= 0.6
    # each message goes out no earlier than its recorded time after the first one; a loaded
    # machine can only make a send late (the same 0.5 s pauses, never shorter)
    sent = [stamp for _, _, stamp in by_send_time]
    early = [
        (m.topic, _gap(sent, 0, k), _gap([r.log_time for r in recorded], 0, k))
        for k, m in enumerate(recorded)
        if _gap(sent, 0, k) < _gap([r.log_time for r in recorded], 0, k) - 0.05
    ]
    assert early == [], early


def test_play_at_rate_two_plays_the_gaps_in_about_half_the_time(ros, processes, scenario_bag):
    listener = Listener(ros, {"/chatter": TYPES["/chatter"]})
    player = _play(processes, scenario_bag, "--rate", "2", "--topics", "/chatter")
    listener.spin_while_running(player)
    assert player.wait(timeout=15) == 0
    chatter = [stamp for _, stamp in listener.on("/chatter")]
    assert len(chatter) == 5
    logged = [m.log_time for m in mcap_messages(scenario_bag, {"/chatter"})]
    # never earlier than half the recorded time after the first message (late sends only
    # make gaps longer) ...
    early = [k for k in range(5) if _gap(chatter, 0, k) < _gap(logged, 0, k) / 2 - 0.05]
    assert early == [], (chatter, logged)
    # ... and the whole run clearly shorter than at rate 1 (the last send would have to be
    # late by a third of the recording for this to fail)
    assert _gap(chatter, 0, 4) < _gap(logged, 0, 4) * 5 / 6, (chatter, logged)


def test_play_topics_and_remap_choose_and_rename_the_topics_played(ros, processes, scenario_bag):
    from rosl.graph.records import PUBLISHER

    listener = Listener(ros, {**TYPES, "/talk": TYPES["/chatter"]})
    player = _play(
        processes, scenario_bag, "--topics", "/chatter", "/numbers", "--remap", "/chatter:=/talk"
    )
    graph = listener.node.participant.graph
    publishers: list[tuple[str, str]] = []

    def seen() -> bool:
        publishers[:] = [
            (node.name, endpoint.type) for node, endpoint in graph.endpoints(PUBLISHER, "/talk")
        ]
        return bool(publishers)

    assert listener.spin_until(seen, timeout=30)
    assert publishers == [("rosbag2_player", "std_msgs/msg/String")]
    listener.spin_while_running(player)
    assert player.wait(timeout=15) == 0
    chatter = [m.data for m in mcap_messages(scenario_bag, {"/chatter"})]
    assert [data for data, _ in listener.on("/talk")] == chatter
    assert len(listener.on("/numbers")) == 3
    assert listener.on("/chatter") == []
    assert listener.on("/pose") == []


def test_play_start_offset_skips_the_first_seconds_of_the_bag(ros, processes, scenario_bag):
    recorded = mcap_messages(scenario_bag)
    start = recorded[0].log_time
    chatter = [m for m in recorded if m.topic == "/chatter"]
    offset = ((chatter[1].log_time + chatter[2].log_time) / 2 - start) / NS  # in the 0.5 s gap
    listener = Listener(ros, {"/chatter": TYPES["/chatter"]})
    player = _play(
        processes, scenario_bag, "--start-offset", f"{offset:.3f}", "--topics", "/chatter"
    )
    listener.spin_while_running(player)
    assert player.wait(timeout=15) == 0
    assert [data for data, _ in listener.on("/chatter")] == [m.data for m in chatter[2:]]


def test_play_clock_makes_a_sim_time_node_follow_the_bag_time(ros, processes, scenario_bag):
    recorded = mcap_messages(scenario_bag)
    start, end = recorded[0].log_time, recorded[-1].log_time
    listener = Listener(
        ros, {"/chatter": TYPES["/chatter"]}, cli_args=["--ros-args", "-p", "use_sim_time:=true"]
    )
    clock = listener.node.get_clock()
    player = _play(processes, scenario_bag, "--clock", "50", "--topics", "/chatter")
    seen: list[int] = []

    def sample() -> bool:
        seen.append(clock.now().nanoseconds)
        return player.poll() is not None

    listener.spin_until(sample, timeout=30)
    assert player.wait(timeout=15) == 0

    def covered() -> bool:  # the last /clock messages may still be on their way: read them
        sample()
        moved = [ns for ns in seen if ns]
        return bool(moved) and moved[-1] - moved[0] >= (end - start) // 2

    listener.spin_until(covered, timeout=10)
    following = [ns for ns in seen if ns]
    assert following, "the node's clock never moved"
    assert all(start <= ns <= end + NS for ns in following)
    assert following == sorted(following)
    assert following[-1] - following[0] >= (end - start) // 2


@pytest.mark.slow
def test_play_loop_plays_the_bag_again_until_stopped(ros, processes, scenario_bag):
    chatter = [m.data for m in mcap_messages(scenario_bag, {"/chatter"})]
    listener = Listener(ros, {"/chatter": TYPES["/chatter"]})
    player = _play(processes, scenario_bag, "--loop", "--topics", "/chatter", "--rate", "4")
    assert listener.spin_until(lambda: len(listener.on("/chatter")) >= 2 * len(chatter), 30)
    player.send_signal(signal.SIGINT)  # once: the loop ends at once, quietly
    out, err = player.communicate(timeout=10)
    heard = [data for data, _ in listener.on("/chatter")]
    assert heard[: 2 * len(chatter)] == chatter + chatter
    assert "passes" in out
    assert "Traceback" not in err, err


@pytest.mark.slow
def test_play_recorded_again_reads_back_identically_with_rosbags_and_mcap(
    processes, scenario_bag, tmp_path
):
    from rosbags.highlevel import AnyReader
    from rosbags.rosbag2 import Reader

    again = tmp_path / "again"
    recorder = processes.rosl("bag", "record", "-a", "-o", str(again))
    output = ChildOutput(recorder)
    deadline = time.monotonic() + 30
    while "Recording to" not in output.text["err"] and time.monotonic() < deadline:
        output._read(0.05)
    assert "Recording to" in output.text["err"], output.text
    player = _play(processes, scenario_bag, "--topics", *TYPES)
    assert player.wait(timeout=30) == 0
    processes.stop(recorder)  # it reads what is still on its sockets before closing the file
    for topic in TYPES:  # per topic: across topics the receive order may differ
        source = [(m.type, m.data) for m in mcap_messages(scenario_bag, {topic})]
        assert [(m.type, m.data) for m in mcap_messages(again, {topic})] == source
    with Reader(again) as reader:
        assert {c.topic: c.msgtype for c in reader.connections if c.topic in TYPES} == TYPES
    with AnyReader([again]) as reader:
        wanted = [c for c in reader.connections if c.topic in TYPES]
        decoded = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(wanted)]
    assert [m.data for m in decoded if hasattr(m, "data") and isinstance(m.data, str)] == [
        "m0", "m1", "m2", "m3", "m4"
    ]  # fmt: skip


def test_play_of_an_unfinished_file_plays_its_complete_messages_and_suggests_reindex(
    processes, scenario_bag, tmp_path
):
    folder = torn_bag(scenario_bag, tmp_path / "torn")
    player = _play(processes, folder)
    out, err = player.communicate(timeout=15)
    assert player.returncode == 0, err
    assert "unfinished" in err
    assert "rosl bag reindex" in err
    assert "played 4 messages" in out
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("layout", "expected"),
    [
        ("missing", "no recording at"),
        ("not_mcap", "is not an MCAP file"),
        ("missing_files", "names files that are not there"),
    ],
)
def test_play_of_a_bad_bag_says_so_in_one_line(processes, scenario_bag, tmp_path, layout, expected):
    target = tmp_path / "bag"
    if layout == "not_mcap":
        target.mkdir()
        (target / "data.mcap").write_text("hello, not a bag\n")
    elif layout == "missing_files":
        shutil.copytree(scenario_bag, target)
        for path in target.glob("*.mcap"):
            path.unlink()
    player = _play(processes, target)
    _, err = player.communicate(timeout=15)
    assert player.returncode == 1
    assert expected in err
    assert len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize(
    ("option", "expected"),
    [
        (("--remap", "/chatter"), "--remap '/chatter' is not of the form from:=to"),
        (("--rate", "0"), "--rate must be greater than 0 (got 0.0)"),
        (("--clock", "0"), "--clock must be a rate greater than 0 Hz (got 0)"),
    ],
)
def test_play_rejects_a_bad_option_value_in_one_line(processes, scenario_bag, option, expected):
    player = _play(processes, scenario_bag, *option)
    _, err = player.communicate(timeout=15)
    assert player.returncode == 1
    assert err.strip() == expected


def test_play_without_a_terminal_prints_no_keyboard_hints(processes, scenario_bag):
    player = _play(processes, scenario_bag, "--topics", "/numbers", "--rate", "10")
    _, err = player.communicate(timeout=15)
    assert player.returncode == 0
    assert "Set rate to 10" in err
    assert "Press SPACE" not in err


def test_play_start_paused_without_a_terminal_says_it_needs_one(processes, scenario_bag):
    player = _play(processes, scenario_bag, "--start-paused")
    _, err = player.communicate(timeout=15)
    assert player.returncode == 1
    assert err.strip().splitlines()[-1] == (
        "--start-paused needs the keyboard: stdin is not a terminal"
    )


def test_play_on_a_terminal_pauses_steps_and_resumes_from_the_keyboard(
    ros, processes, scenario_bag
):
    import os
    import pty
    import termios

    from rosl.graph.records import PUBLISHER

    master, terminal = pty.openpty()
    before = termios.tcgetattr(terminal)
    listener = Listener(ros, {"/chatter": TYPES["/chatter"]})
    player = processes.rosl(
        "bag", "play", str(scenario_bag), "--topics", "/chatter", "--start-paused",
        stdin=terminal,
    )  # fmt: skip
    graph = listener.node.participant.graph
    try:
        assert listener.spin_until(lambda: graph.count(PUBLISHER, "/chatter") > 0, timeout=30)
        # unpaused, the first message would go out some 0.3 s after the player announced itself;
        # 2 s leave room for a loaded machine, so that this can fail when pausing is broken
        end = time.monotonic() + 2.0
        listener.spin_until(lambda: time.monotonic() > end, 3.0)
        assert listener.on("/chatter") == []  # paused: nothing flows
        os.write(master, b"\x1b[C")
        assert listener.spin_until(lambda: len(listener.on("/chatter")) == 1, timeout=15)
        os.write(master, b"\x1b[C")
        assert listener.spin_until(lambda: len(listener.on("/chatter")) == 2, timeout=15)
        os.write(master, b" ")
        listener.spin_while_running(player)
        _, err = player.communicate(timeout=15)
        after = termios.tcgetattr(terminal)
    finally:
        os.close(master)
        os.close(terminal)
    assert player.returncode == 0, err
    chatter = [m.data for m in mcap_messages(scenario_bag, {"/chatter"})]
    assert [data for data, _ in listener.on("/chatter")] == chatter
    assert "Press SPACE for Pause/Resume" in err
    assert "Press CURSOR_RIGHT for Play Next Message" in err
    assert "Resuming play." in err
    assert after == before  # the terminal's mode is restored


def test_play_keeps_transient_local_topics_for_late_subscribers(ros, processes, tmp_path):
    from mcap.writer import Writer

    from rosl.idl.registry import get_message_class, store
    from rosl.node.qos import DurabilityPolicy, QoSProfile

    string = get_message_class("std_msgs/msg/String")
    qos = "- {history: keep_last, depth: 1, reliability: reliable, durability: transient_local}\n"
    folder = tmp_path / "latched"
    folder.mkdir()
    with (folder / "latched_0.mcap").open("wb") as handle:
        writer = Writer(handle)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema("std_msgs/msg/String", "ros2msg", b"string data\n")
        channel = writer.register_channel("/map_name", "cdr", schema, {"offered_qos_profiles": qos})
        for index, text in enumerate(["first map", "second map"]):  # 20 s apart
            data = store().serialize(string(data=text))
            writer.add_message(channel, index * 20 * NS, data, index * 20 * NS)
        writer.finish()
    listener = Listener(ros, {"/map_name": "std_msgs/msg/String"})
    player = _play(processes, folder)
    assert listener.spin_until(lambda: len(listener.on("/map_name")) == 1, timeout=30)
    late: list[str] = []
    listener.node.create_subscription(
        string, "/map_name", lambda m: late.append(m.data),
        QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL),
    )  # fmt: skip
    assert listener.spin_until(lambda: late == ["first map"], timeout=15)
    processes.stop(player)
