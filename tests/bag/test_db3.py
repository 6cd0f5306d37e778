"""rosbag2's sqlite3 storage: ``.db3`` bags read by every bag command, and MCAP <-> db3.

The bags are made by an outside writer — rosbags' ``rosbag2.Writer`` (sqlite3, metadata
versions 8 and 9) — and, for the layouts older rosbag2 releases wrote (no ``schema`` table,
no QoS column, no message definitions), with SQLite itself from those layouts' tables. Every
layout holds the same messages, written out of time order, with two of them at the same time.
"""

from __future__ import annotations

import json
import shutil
import sqlite3
import subprocess
import sys
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest
import yaml
from rosbags.highlevel import AnyReader
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import Reader, StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from rosl.bag.reader import iter_bag
from rosl.bag.trim import scan
from rosl.cli.main import main
from tests.bag.conftest import Listener, mcap_messages
from tests.bag_record import support
from tests.conftest import REPO

if TYPE_CHECKING:
    from pathlib import Path

NS = 1_000_000_000
BASE = 1_700_000_000 * NS
STORE = get_typestore(Stores.ROS2_HUMBLE)
TYPES = {
    "/chatter": "std_msgs/msg/String",
    "/pose": "geometry_msgs/msg/PoseStamped",
    "/odom": "nav_msgs/msg/Odometry",
}
RELIABLE = Qos(
    QosHistory.KEEP_LAST, 10, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL,
    QosTime(2147483647, 4294967295), QosTime(2147483647, 4294967295), QosLiveliness.AUTOMATIC,
    QosTime(2147483647, 4294967295), False,
)  # fmt: skip
OLD_TOPICS = {  # the topics table as older rosbag2 releases made it
    "dashing": "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE, "
    "type TEXT NOT NULL, serialization_format TEXT NOT NULL)",
    "foxy": "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE, "
    "type TEXT NOT NULL, serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)",
    "humble": "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
    " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)",
}
MESSAGES_TABLE = (
    "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
    "timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
)


@dataclass(frozen=True)
class Sent:
    """One message as written to the bags."""

    topic: str
    timestamp: int
    data: bytes

    @property
    def type(self) -> str:
        return TYPES[self.topic]


def _message(topic: str, k: int) -> Any:
    t = STORE.types
    stamp = t["builtin_interfaces/msg/Time"](sec=1_700_000_000 + k, nanosec=k * 1000)
    if topic == "/chatter":
        return t["std_msgs/msg/String"](data=f"hello {k} ünïcode")
    pose = t["geometry_msgs/msg/Pose"](
        position=t["geometry_msgs/msg/Point"](x=0.5 * k, y=-1.25 * k, z=0.0),
        orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.6, w=0.8),
    )
    if topic == "/pose":
        header = t["std_msgs/msg/Header"](stamp=stamp, frame_id="map")
        return t["geometry_msgs/msg/PoseStamped"](header=header, pose=pose)
    zero = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
    return t["nav_msgs/msg/Odometry"](
        header=t["std_msgs/msg/Header"](stamp=stamp, frame_id="odom"),
        child_frame_id="base_link",
        pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=pose, covariance=np.arange(36.0)),
        twist=t["geometry_msgs/msg/TwistWithCovariance"](
            twist=t["geometry_msgs/msg/Twist"](
                linear=t["geometry_msgs/msg/Vector3"](x=0.2 * k, y=0.0, z=0.0), angular=zero
            ),
            covariance=np.zeros(36),
        ),
    )


def _written() -> list[Sent]:
    """The messages in the order they are written: /odom last, though it starts first."""
    sent = []
    for topic, offset in (("/chatter", 0), ("/pose", 50), ("/odom", 0)):
        for k in range(4):
            at = BASE + (offset + 100 * k) * 1_000_000
            sent.append(
                Sent(topic, at, bytes(STORE.serialize_cdr(_message(topic, k), TYPES[topic])))
            )
    return sent


WRITTEN = _written()
# rosbag2's order: by timestamp, then as written (/chatter k and /odom k share a time)
IN_ORDER = [m for _, m in sorted(enumerate(WRITTEN), key=lambda p: (p[1].timestamp, p[0]))]


def _rosbags_bag(folder: Path, version: int) -> Path:
    with Writer(folder, version=version, storage_plugin=StoragePlugin.SQLITE3) as writer:  # type: ignore[arg-type]
        connections = {
            topic: writer.add_connection(
                topic, type_name, typestore=STORE,
                offered_qos_profiles=[RELIABLE] if topic == "/pose" else [],
            )
            for topic, type_name in TYPES.items()
        }  # fmt: skip
        for message in WRITTEN:
            writer.write(connections[message.topic], message.timestamp, message.data)
    return folder


def _old_bag(folder: Path, layout: str) -> Path:
    """A folder with only a .db3 file, in the tables an older rosbag2 made (no metadata.yaml)."""
    folder.mkdir()
    db = sqlite3.connect(folder / f"{folder.name}_0.db3")
    if layout == "humble":
        db.executescript(
            "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
            "INSERT INTO schema VALUES (3, 'humble');"
            "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, "
            "metadata TEXT NOT NULL);"
        )
    db.executescript(f"{OLD_TOPICS[layout]};{MESSAGES_TABLE}")
    qos = "- history: 1\n  depth: 10\n  reliability: 1\n  durability: 1\n"  # Humble's numbers
    for number, (topic, type_name) in enumerate(TYPES.items(), start=1):
        row = [number, topic, type_name, "cdr"] + ([qos] if layout != "dashing" else [])
        db.execute(f"INSERT INTO topics VALUES ({', '.join('?' * len(row))})", row)
    ids = {topic: number for number, topic in enumerate(TYPES, start=1)}
    db.executemany(
        "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)",
        [(ids[m.topic], m.timestamp, m.data) for m in WRITTEN],
    )
    db.commit()
    db.close()
    return folder


@pytest.fixture(scope="module")
def bags(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The same messages in every layout: rosbags' v8 and v9, and three older rosbag2 ones."""
    root = tmp_path_factory.mktemp("db3")
    made = {f"v{v}": _rosbags_bag(root / f"v{v}", v) for v in (8, 9)}
    made.update({layout: _old_bag(root / layout, layout) for layout in OLD_TOPICS})
    return made


def run(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[int, str, str]:
    code = main(["bag", *[str(a) for a in args]])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def rosl_process(*args: object) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rosl", *[str(a) for a in args]], capture_output=True, text=True,
        timeout=60, cwd=REPO, check=False, stdin=subprocess.DEVNULL,
    )  # fmt: skip


def _rows(messages: list[Any]) -> list[tuple[str, str, int, bytes]]:
    return [(m.topic, m.type, m.log_time, bytes(m.data)) for m in messages]


EXPECTED = [(m.topic, m.type, m.timestamp, m.data) for m in IN_ORDER]


# --- reading -------------------------------------------------------------------------------------


def test_every_layout_reads_back_every_message_in_rosbag2s_order(bags):
    for name, bag in bags.items():
        messages = list(iter_bag(bag))
        assert _rows(messages) == EXPECTED, name
        assert all(m.publish_time == m.log_time and m.sequence == 0 for m in messages)
        pose = next(m for m in messages if m.topic == "/pose")
        assert pose.schema_encoding == "ros2msg", name
        assert "MSG: geometry_msgs/Pose" in pose.schema_text, name  # its dependencies too
        assert _rows(iter_bag(bag, {"/pose", "/odom"})) == [
            row for row in EXPECTED if row[0] in ("/pose", "/odom")
        ], name


def test_a_single_db3_file_is_a_bag_and_its_qos_and_hash_come_along(bags):
    (path,) = bags["v9"].glob("*.db3")
    assert _rows(iter_bag(path)) == EXPECTED
    found = scan(path)
    assert {name: c.count for name, c in found.channels.items()} == {t: 4 for t in TYPES}
    assert (found.start_ns, found.end_ns, found.count) == (BASE, BASE + 350_000_000, 12)
    assert found.unfinished == []
    pose = found.channels["/pose"]
    assert pose.type == TYPES["/pose"]
    assert pose.offered_qos()[0]["durability"] == "transient_local"
    assert pose.metadata["topic_type_hash"] == STORE.hash_rihs01(TYPES["/pose"])
    old = scan(bags["foxy"]).channels["/pose"]  # the QoS numbers of rmw read as words
    assert old.offered_qos()[0]["reliability"] == "reliable"


def test_rosl_reads_what_rosbags_reads(bags):
    for name in ("v8", "v9"):
        with AnyReader([bags[name]]) as reader:
            theirs = sorted((c.topic, c.msgtype, t, bytes(raw)) for c, t, raw in reader.messages())
        assert sorted(_rows(iter_bag(bags[name]))) == theirs, name


# --- the commands --------------------------------------------------------------------------------


def test_bag_info_describes_a_db3_bag(capsys, bags):
    code, out, err = run(capsys, "info", bags["v9"])
    assert code == 0, err
    assert "Storage id:        sqlite3" in out
    assert "Messages:          12" in out
    assert "Duration:          0.350000000s" in out
    for topic, type_name in TYPES.items():
        assert f"Topic: {topic} | Type: {type_name} | Count: 4 | Serialization Format: cdr" in out
    code, out, _ = run(capsys, "info", bags["dashing"], "--json")
    assert code == 0
    data = json.loads(out)
    assert (data["start_ns"], data["end_ns"], data["messages"]) == (BASE, BASE + 350 * 10**6, 12)
    assert data["unfinished"] == []
    assert data["files"] == ["dashing_0.db3"]


def test_bag_diff_matches_a_db3_bag_with_itself_its_other_layouts_and_its_mcap(
    capsys, bags, tmp_path
):
    assert run(capsys, "diff", bags["v9"], bags["v9"])[0] == 0
    for other in ("v8", "dashing", "humble"):
        code, out, _ = run(capsys, "diff", bags["v9"], bags[other])
        assert code == 0, (other, out)
        assert "bags match: 12 messages on 3 topics" in out
    assert run(capsys, "convert", bags["foxy"], tmp_path / "as_mcap")[0] == 0
    code, out, _ = run(capsys, "diff", bags["v9"], tmp_path / "as_mcap")
    assert (code, out.strip()) == (0, "bags match: 12 messages on 3 topics")
    changed = shutil.copytree(bags["v9"], tmp_path / "changed")
    pose = next(m for m in IN_ORDER if m.topic == "/pose")
    moved = _message("/pose", 0)
    moved.pose.position.x = 7.0
    with sqlite3.connect(changed / "v9.db3") as db:  # the copy's first /pose, moved to x = 7
        db.execute(
            "UPDATE messages SET data = ? WHERE timestamp = ? AND topic_id = "
            "(SELECT id FROM topics WHERE name = '/pose')",
            (bytes(STORE.serialize_cdr(moved, TYPES["/pose"])), pose.timestamp),
        )
    code, out, _ = run(capsys, "diff", bags["v9"], changed)
    assert code == 1
    assert "pose.position.x" in out
    assert "bags differ: 1 difference(s)" in out


def test_bag_filter_of_a_db3_bag_keeps_the_window_and_topics(capsys, bags, tmp_path):
    out_bag = tmp_path / "window"
    code, out, err = run(
        capsys, "filter", bags["humble"], out_bag, "--topics", "/pose", "/odom",
        "--start", "0.1", "--end", "0.25",
    )  # fmt: skip
    assert code == 0, err
    kept = [m for m in EXPECTED if m[0] != "/chatter" and BASE + NS // 10 <= m[2] <= BASE + NS // 4]
    assert [r[0] for r in kept] == ["/odom", "/pose", "/odom", "/pose"]
    assert [(m.topic, m.type, m.log_time, m.data) for m in mcap_messages(out_bag)] == kept
    assert f"wrote 4 of 12 messages on 2 topics to '{out_bag}'" in out


def _outside_mcap(bag: Path) -> list[tuple[str, str, int, bytes]]:
    """The MCAP bag as rosbags' AnyReader reads it: every message decoded as well."""
    with AnyReader([bag]) as reader:
        rows = [(c.topic, c.msgtype, t, bytes(raw)) for c, t, raw in reader.messages()]
        first = next(c for c in reader.connections if c.topic == "/odom")
        odom = reader.deserialize(
            next(raw for c, _, raw in reader.messages([first])), first.msgtype
        )
    assert odom.pose.pose.orientation.w == 0.8
    assert list(odom.pose.covariance) == list(np.arange(36.0))
    return sorted(rows, key=lambda r: (r[2], r[0]))


def _tables(path: Path) -> dict[str, Any]:
    with sqlite3.connect(path) as db:
        return {
            "names": {row[0] for row in db.execute("SELECT name FROM sqlite_master")},
            "schema": db.execute("SELECT schema_version, ros_distro FROM schema").fetchall(),
            "definitions": dict(
                db.execute("SELECT topic_type, encoding FROM message_definitions").fetchall()
            ),
            "metadata": db.execute("SELECT metadata_version, metadata FROM metadata").fetchall(),
            "hashes": dict(db.execute("SELECT name, type_description_hash FROM topics")),
        }


def test_bag_convert_db3_to_mcap_and_back_keeps_every_message(capsys, bags, tmp_path):
    as_mcap, back = tmp_path / "as_mcap", tmp_path / "back"
    assert run(capsys, "convert", bags["v9"], as_mcap)[0] == 0
    assert [(m.topic, m.type, m.log_time, m.data) for m in mcap_messages(as_mcap)] == EXPECTED
    assert _outside_mcap(as_mcap) == sorted(EXPECTED, key=lambda r: (r[2], r[0]))
    code, out, err = run(capsys, "convert", as_mcap, back, "--storage", "sqlite3")
    assert code == 0, err
    assert f"wrote 12 of 12 messages on 3 topics to '{back}'" in out
    information = yaml.safe_load((back / "metadata.yaml").read_text())[
        "rosbag2_bagfile_information"
    ]
    assert information["storage_identifier"] == "sqlite3"
    assert information["relative_file_paths"] == ["back_0.db3"]
    with Reader(back) as reader:  # rosbags' own reader, from metadata.yaml and the file
        assert {c.topic: (c.msgtype, c.msgcount) for c in reader.connections} == {
            topic: (type_name, 4) for topic, type_name in TYPES.items()
        }
        pose = next(c for c in reader.connections if c.topic == "/pose")
        assert pose.ext.offered_qos_profiles[0].durability == QosDurability.TRANSIENT_LOCAL
        theirs = [(c.topic, c.msgtype, t, bytes(raw)) for c, t, raw in reader.messages()]
    assert sorted(theirs, key=lambda r: (r[2], r[0])) == sorted(
        EXPECTED, key=lambda r: (r[2], r[0])
    )
    tables = _tables(back / "back_0.db3")
    assert tables["hashes"]["/pose"] == STORE.hash_rihs01(TYPES["/pose"])
    assert {"schema", "metadata", "topics", "message_definitions", "messages",
            "timestamp_idx"} <= tables["names"]  # fmt: skip
    assert tables["schema"] == [(4, information["ros_distro"])]
    assert tables["definitions"] == dict.fromkeys(TYPES.values(), "ros2msg")
    ((version, text),) = tables["metadata"]
    assert (version, yaml.safe_load(text)["message_count"]) == (information["version"], 12)
    assert run(capsys, "diff", bags["v9"], back)[0] == 0


def test_bag_convert_between_db3_bags_describes_types_an_old_file_did_not(capsys, bags, tmp_path):
    out_bag = tmp_path / "new"
    code, _, err = run(capsys, "convert", bags["dashing"], out_bag, "-s", "sqlite3", "--distro",
                       "jazzy")  # fmt: skip
    assert code == 0, err
    with Reader(out_bag) as reader:  # version 9 metadata names the type hashes too
        assert reader.ros_distro == "jazzy"
        assert {c.topic: c.digest for c in reader.connections} == {
            topic: STORE.hash_rihs01(type_name) for topic, type_name in TYPES.items()
        }
    with AnyReader([out_bag]) as reader:  # decoding needs the definitions the new file holds
        decoded = [
            (c.topic, t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages()
        ]
    pose = [message for topic, _, message in decoded if topic == "/pose"]
    assert [p.pose.position.x for p in pose] == [0.0, 0.5, 1.0, 1.5]
    assert sorted(_rows(iter_bag(out_bag))) == sorted(EXPECTED)


def test_bag_convert_to_sqlite3_refuses_a_chunk_compression(capsys, bags, tmp_path):
    code, _, err = run(capsys, "convert", bags["v9"], tmp_path / "x", "-s", "sqlite3",
                       "--compression-format", "zstd")  # fmt: skip
    assert code == 2
    assert "--compression-format" in err
    assert not (tmp_path / "x").exists()


def test_viz_draws_a_db3_bag(bags, tmp_path):
    picture = tmp_path / "odom.png"
    assert main(["viz", str(bags["v8"]), "-o", str(picture)]) == 0
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_bag_play_of_a_db3_bag_sends_the_recorded_bytes(ros, processes, bags):
    listener = Listener(ros, TYPES)
    player = processes.rosl("bag", "play", str(bags["v9"]))
    listener.spin_while_running(player)
    _, err = player.communicate(timeout=15)
    assert player.returncode == 0, err
    for topic in TYPES:
        assert [data for data, _ in listener.on(topic)] == [
            m.data for m in IN_ORDER if m.topic == topic
        ], topic


# --- bad inputs ----------------------------------------------------------------------------------


def _bad_bags(root: Path) -> dict[str, Path]:
    garbage = root / "garbage.db3"
    garbage.write_bytes(b"this is not a database at all" * 40)
    in_folder = root / "folder_bag"
    in_folder.mkdir()
    shutil.copy(garbage, in_folder / "folder_bag_0.db3")
    no_messages = root / "no_messages.db3"
    with sqlite3.connect(no_messages) as db:
        db.execute(OLD_TOPICS["foxy"])
    db.close()
    compressed = root / "compressed"
    compressed.mkdir()
    (compressed / "metadata.yaml").write_text(
        yaml.safe_dump(
            {
                "rosbag2_bagfile_information": {
                    "version": 5,
                    "storage_identifier": "sqlite3",
                    "compression_mode": "FILE",
                    "compression_format": "zstd",
                    "relative_file_paths": ["compressed_0.db3.zstd"],
                }
            }
        )
    )
    return {"garbage": garbage, "in_folder": in_folder, "no_messages": no_messages,
            "compressed": compressed}  # fmt: skip


@pytest.mark.parametrize(
    ("command", "which", "says"),
    [
        (("bag", "info"), "garbage", "garbage.db3 is not a rosbag2 sqlite3 file"),
        (("bag", "diff", "{0}"), "in_folder", "folder_bag_0.db3 is not a rosbag2 sqlite3 file"),
        (("bag", "info"), "no_messages", "no_messages.db3 is not a rosbag2 sqlite3 file (it "
         "has no 'messages' table)"),
        (("bag", "convert", "{out}", "-s", "sqlite3"), "no_messages", "no 'messages' table"),
        (("bag", "play"), "compressed", "FILE compression (zstd)"),
    ],
)  # fmt: skip
def test_a_bad_db3_is_one_line_naming_it(tmp_path, command, which, says):
    bad = _bad_bags(tmp_path)[which]
    words = [w.format(out=tmp_path / "out") for w in command[:2]]
    extra = [w.format(bad, out=tmp_path / "out") for w in command[2:]]
    line = support.one_line_error(rosl_process(*words, bad, *extra))
    assert says in line, line
    assert not (tmp_path / "out").exists()
