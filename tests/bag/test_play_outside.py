"""``rosl bag play`` of bags written by other tools: relative names, late statistics, json.

A topic stored as ``AAA`` is played on ``/AAA``, as the ROS 2 player's publishers resolve it in
the namespace ``/``; the bag's start is its first message, not what its Statistics record
claims; a channel that is not CDR is refused in rosbag2's words. A rosl node in this process
(``Listener``) hears what the player sends.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pytest

from tests.bag.conftest import Listener
from tests.bag.test_info_options import cdr_string, json_bag, write_mcap, zero_start_bag

if TYPE_CHECKING:
    from pathlib import Path

NS = 1_000_000_000
STRING = "std_msgs/msg/String"
TEXTS = ["one", "two", "three"]


def by_mcap_writer(folder: Path) -> Path:
    folder.mkdir()
    write_mcap(
        folder / "relative.mcap",
        [("AAA", STRING, 1_000 * NS + k * NS // 10, cdr_string(text))
         for k, text in enumerate(TEXTS)],
    )  # fmt: skip
    return folder


def by_rosbags_writer(folder: Path) -> Path:
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    with Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection("AAA", STRING, typestore=store)
        for k, text in enumerate(TEXTS):
            writer.write(connection, 1_000 * NS + k * NS // 10, cdr_string(text))
    return folder


@pytest.mark.parametrize(
    ("write", "args"),
    [(by_mcap_writer, ()), (by_rosbags_writer, ("--topics", "AAA"))],
    ids=["mcap_writer", "rosbags_writer_topics_relative"],
)
def test_play_sends_a_relative_topic_name_on_its_absolute_name(
    ros, processes, tmp_path, write, args
):
    bag = write(tmp_path / "bag")
    listener = Listener(ros, {"/AAA": STRING})
    player = processes.rosl("bag", "play", str(bag), *args)
    listener.spin_while_running(player)
    out, err = player.communicate(timeout=15)
    assert player.returncode == 0, err
    assert [data for data, _ in listener.on("/AAA")] == [cdr_string(text) for text in TEXTS]
    assert "played 3 messages: /AAA 3" in out
    assert "not in the bag" not in err


def test_play_remaps_a_relative_topic_name(ros, processes, tmp_path):
    bag = by_mcap_writer(tmp_path / "bag")
    listener = Listener(ros, {"/AAA": STRING, "/renamed": STRING})
    player = processes.rosl("bag", "play", str(bag), "--remap", "AAA:=renamed", "--rate", "5")
    listener.spin_while_running(player)
    out, err = player.communicate(timeout=15)
    assert player.returncode == 0, err
    assert [data for data, _ in listener.on("/renamed")] == [cdr_string(text) for text in TEXTS]
    assert listener.on("/AAA") == []
    assert "played 3 messages: /renamed 3" in out


def test_play_starts_at_the_first_message_not_where_the_statistics_say(ros, processes, tmp_path):
    """/zero holds messages at 0, 1 s and 2 s; the summary claims the bag starts at 1 s.
    Half a second into the bag is past the first message only: two are played."""
    path = zero_start_bag(tmp_path / "zero")
    listener = Listener(ros, {"/zero": STRING})
    player = processes.rosl("bag", "play", str(path), "--start-offset", "0.5", "--rate", "2")
    listener.spin_while_running(player)
    out, err = player.communicate(timeout=15)
    assert player.returncode == 0, err
    assert [data for data, _ in listener.on("/zero")] == [cdr_string("z1"), cdr_string("z2")]
    assert "played 2 messages" in out
    assert "Playing 3 messages on 1 topics (2.0 s of recording)" in err
    assert "unfinished" not in err


def test_play_refuses_a_channel_that_is_not_cdr_in_one_line(processes, tmp_path):
    folder = json_bag(tmp_path / "mixed")
    player = processes.rosl("bag", "play", str(folder))
    out, err = player.communicate(timeout=15)
    assert player.returncode == 1
    assert err.splitlines() == ["Could not find converter for format json (topic /data)"]
    # the cdr topic alone can be played
    player = processes.rosl("bag", "play", str(folder), "--topics", "/ok")
    out, err = player.communicate(timeout=15)
    assert player.returncode == 0, err
    assert "played 1 messages: /ok 1" in out
