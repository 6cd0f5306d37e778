"""One recording of real traffic, checked against rosbag2's folder and MCAP layout.

``rosl bag record -a`` runs as a child; a publisher child then sends Strings (depth 7,
transient local), Twists and JointStates (best effort, depth 3) and logs two lines; after it,
a second publisher brings a topic the recorder has not seen yet. The bag is read back with
``metadata.yaml``, ``mcap``'s reader, ``rosbags.rosbag2.Reader`` and ``AnyReader`` and
compared with the bytes and fields the publishers sent.
"""

from __future__ import annotations

import signal
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import pytest
import yaml

from rosl.idl import registry
from tests.bag_record import support

if TYPE_CHECKING:
    from pathlib import Path

    from tests.bag_record.conftest import DomainProcesses

CHATTER = {
    "topic": "/chatter",
    "type": "std_msgs/msg/String",
    "qos": {"depth": 7, "durability": "TRANSIENT_LOCAL"},
}
CMD_VEL = {"topic": "/cmd_vel", "type": "geometry_msgs/msg/Twist", "qos": {"depth": 10}}
JOINTS = {
    "topic": "/joints",
    "type": "sensor_msgs/msg/JointState",
    "qos": {"depth": 3, "reliability": "BEST_EFFORT"},
}
LATE = {"topic": "/late_counter", "type": "std_msgs/msg/Int32", "qos": {"depth": 10}}
PUBLISHERS = [CHATTER, CMD_VEL, JOINTS]

MESSAGES: list[tuple[int, dict[str, Any]]] = [
    *[(0, {"data": f"hello {i} ünïcode"}) for i in range(5)],
    *[
        (1, {"linear": {"x": 0.5 * i, "y": -1.25, "z": 1e-9}, "angular": {"z": 3.0 - i}})
        for i in range(4)
    ],
    *[
        (
            2,
            {
                "header": {"stamp": {"sec": 100 + i, "nanosec": 7 * i}, "frame_id": f"base_{i}"},
                "name": ["shoulder", "elbow", "wrist"][: i + 1],
                "position": [0.1 * k for k in range(i + 1)],
                "velocity": [],
                "effort": [-1.5] * i,
            },
        )
        for i in range(3)
    ],
]
LATE_MESSAGES = [(0, {"data": value}) for value in (-7, 0, 2147483647)]
LOG_LINES = ["bag test says hello", "bag test says goodbye"]


@dataclass
class Recording:
    folder: Path
    sent: dict[str, list[dict[str, Any]]]  # topic -> fields, in order
    times: dict[str, list[dict[str, int]]]  # topic -> send times, in order
    stderr: str


@pytest.fixture(scope="module")
def recording(module_bus: DomainProcesses, module_dir: Path) -> Recording:
    folder = module_dir / "run1"
    recorder = support.start_recorder(module_bus, "-a", "-o", str(folder), cwd=module_dir)
    first = support.run_publisher(
        module_bus,
        {
            "node": "format_talker",
            "publishers": PUBLISHERS,
            "messages": MESSAGES,
            "log": LOG_LINES,
            "period": 0.01,
        },
        cwd=module_dir,
    )
    # a topic the recorder has not seen before; it must be picked up as it appears
    second = support.run_publisher(
        module_bus,
        {"node": "late_talker", "publishers": [LATE], "messages": LATE_MESSAGES},
        cwd=module_dir,
    )
    stderr = support.stop_recorder(recorder, signal.SIGINT)
    sent: dict[str, list[dict[str, Any]]] = {}
    times: dict[str, list[dict[str, int]]] = {}
    for publishers, messages, stamps in (
        (PUBLISHERS, MESSAGES, first),
        ([LATE], LATE_MESSAGES, second),
    ):
        assert len(stamps) == len(messages)
        for (which, fields), stamp in zip(messages, stamps, strict=True):
            topic = publishers[which]["topic"]
            sent.setdefault(topic, []).append(fields)
            times.setdefault(topic, []).append(stamp)
    return Recording(folder, sent, times, stderr)


TYPES = {p["topic"]: p["type"] for p in [*PUBLISHERS, LATE]}


@pytest.fixture(scope="module")
def jazzy(recording: Recording, module_dir: Path) -> Path:
    """The recording rewritten with Jazzy's metadata layout (``rosl bag convert --distro``)."""
    from rosl.bag.trim import copy

    folder = module_dir / "jazzy"
    copy(recording.folder, folder, ros_distro="jazzy")
    return folder


def qos_of(folder: Path) -> dict[str, list[dict[str, Any]]]:
    """Each topic's offered_qos_profiles in metadata.yaml, parsed (a YAML text before v9)."""
    found = {}
    for entry in support.metadata(folder)["topics_with_message_count"]:
        profiles = entry["topic_metadata"]["offered_qos_profiles"]
        found[entry["topic_metadata"]["name"]] = (
            yaml.safe_load(profiles) if isinstance(profiles, str) else profiles
        )
    return found


def test_the_folder_is_a_rosbag2_folder_in_humbles_layout_with_mcap_storage(
    recording: Recording, jazzy: Path
) -> None:
    info = support.metadata(recording.folder)
    assert (info["version"], info["ros_distro"]) == (5, "humble")  # what Humble's rosbag2 parses
    assert support.metadata(jazzy)["version"] == 9
    assert info["storage_identifier"] == "mcap"
    files = sorted(p.name for p in recording.folder.iterdir())
    assert files == sorted(["metadata.yaml", *info["relative_file_paths"]])
    assert all(name.endswith(".mcap") for name in info["relative_file_paths"])
    assert [f["path"] for f in info["files"]] == info["relative_file_paths"]


def test_metadata_counts_equal_what_was_published(recording: Recording) -> None:
    counts = support.topic_counts(recording.folder)
    for topic, fields in recording.sent.items():
        assert counts.get(topic) == len(fields), (topic, counts)
    info = support.metadata(recording.folder)
    assert info["message_count"] == sum(counts.values())
    assert sum(f["message_count"] for f in info["files"]) == info["message_count"]


def test_metadata_names_each_topics_type_and_cdr_serialization(recording: Recording) -> None:
    entries = {
        e["topic_metadata"]["name"]: e["topic_metadata"]
        for e in support.metadata(recording.folder)["topics_with_message_count"]
    }
    for topic, type_name in TYPES.items():
        assert entries[topic]["type"] == type_name
        assert entries[topic]["serialization_format"] == "cdr"


def test_offered_qos_profiles_repeat_the_publishers_qos_in_each_layouts_form(
    recording: Recording, jazzy: Path
) -> None:
    # rmw's enum numbers in a YAML text up to version 8 (rosbag2_storage qos.cpp), words in 9
    numbers = qos_of(recording.folder)
    words = qos_of(jazzy)
    assert isinstance(support.metadata(recording.folder)["topics_with_message_count"][0][
        "topic_metadata"]["offered_qos_profiles"], str)  # fmt: skip
    expected = {
        "/chatter": ({"depth": 7, "durability": 1, "reliability": 1},
                     {"depth": 7, "durability": "transient_local", "reliability": "reliable"}),
        "/cmd_vel": ({"depth": 10, "durability": 2, "reliability": 1},
                     {"depth": 10, "durability": "volatile", "reliability": "reliable"}),
        "/joints": ({"depth": 3, "durability": 2, "reliability": 2},
                    {"depth": 3, "durability": "volatile", "reliability": "best_effort"}),
    }  # fmt: skip
    for topic, (as_numbers, as_words) in expected.items():
        assert len(numbers[topic]) == len(words[topic]) == 1, numbers[topic]
        assert {k: numbers[topic][0][k] for k in as_numbers} == as_numbers, topic
        assert {k: words[topic][0][k] for k in as_words} == as_words, topic
        assert (numbers[topic][0]["history"], words[topic][0]["history"]) == (1, "keep_last")


def test_type_hashes_are_rosbags_rihs01_of_the_type(recording: Recording, jazzy: Path) -> None:
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    entries = {
        e["topic_metadata"]["name"]: e["topic_metadata"]
        for e in support.metadata(jazzy)["topics_with_message_count"]
    }
    channels = {t: c for f in support.read_mcap(recording.folder) for t, c in f.channels.items()}
    for topic, type_name in TYPES.items():
        expected = support.rihs01(type_name, "ros2msg", registry.msgdef_text(type_name))
        assert entries[topic]["type_description_hash"] == expected, topic
        assert channels[topic].metadata["topic_type_hash"] == expected, topic
        assert expected == store.hash_rihs01(type_name)


def test_each_mcap_file_has_the_ros2_profile(recording: Recording) -> None:
    files = support.read_mcap(recording.folder)
    assert files
    assert all(f.profile == "ros2" for f in files)


def test_schemas_are_ros2msg_with_the_full_message_definition(recording: Recording) -> None:
    for mcap_file in support.read_mcap(recording.folder):
        for type_name, (encoding, text) in mcap_file.schemas.items():
            assert encoding == "ros2msg", type_name
            assert text == registry.msgdef_text(type_name), type_name
    # JointState's definition carries its dependencies, as rosbag2 writes them
    schemas = {k: v for f in support.read_mcap(recording.folder) for k, v in f.schemas.items()}
    joint_state = schemas["sensor_msgs/msg/JointState"][1]
    assert "\nMSG: std_msgs/Header\n" in joint_state  # as rosbag2 writes: no /msg/
    assert "\nMSG: builtin_interfaces/Time\n" in joint_state


def test_channels_carry_cdr_messages_and_the_offered_qos(recording: Recording, jazzy: Path) -> None:
    for folder in (recording.folder, jazzy):
        meta = qos_of(folder)
        for mcap_file in support.read_mcap(folder):
            for topic, channel in mcap_file.channels.items():
                assert channel.message_encoding == "cdr", topic
                assert yaml.safe_load(channel.metadata["offered_qos_profiles"]) == meta[topic]


def test_each_file_ends_with_rosbag2s_metadata_record(recording: Recording, jazzy: Path) -> None:
    from mcap.reader import make_reader

    for folder, version in ((recording.folder, 5), (jazzy, 9)):
        for path in sorted(folder.glob("*.mcap")):
            with path.open("rb") as handle:
                records = [m for m in make_reader(handle).iter_metadata() if m.name == "rosbag2"]
            assert len(records) == 1, path
            assert records[0].metadata["ROS_DISTRO"] == support.metadata(folder)["ros_distro"]
            serialized = yaml.safe_load(records[0].metadata["serialized_metadata"])
            assert serialized["version"] == version
            assert serialized["message_count"] == support.metadata(folder)["message_count"]


def test_payloads_are_exactly_the_cdr_bytes_the_publisher_sent(recording: Recording) -> None:
    messages = support.by_topic(
        [m for f in support.read_mcap(recording.folder) for m in f.messages]
    )
    for topic, fields in recording.sent.items():
        expected = [support.cdr(TYPES[topic], f) for f in fields]
        assert [m.data for m in messages[topic]] == expected, topic


def test_publish_time_is_the_send_time_and_not_after_log_time(recording: Recording) -> None:
    messages = support.by_topic(
        [m for f in support.read_mcap(recording.folder) for m in f.messages]
    )
    for topic, times in recording.times.items():
        assert len(messages[topic]) == len(times)
        for message, sent in zip(messages[topic], times, strict=True):
            assert sent["before"] <= message.publish_time <= sent["after"], topic
            assert message.publish_time <= message.log_time, topic


def test_sequence_numbers_count_from_one_per_channel(recording: Recording) -> None:
    messages = support.by_topic(
        [m for f in support.read_mcap(recording.folder) for m in f.messages]
    )
    assert set(recording.sent) <= set(messages)
    for topic, found in messages.items():
        assert [m.sequence for m in found] == list(range(1, len(found) + 1)), topic


def test_mcap_decoding_gives_the_fields_that_were_sent(recording: Recording) -> None:
    messages = support.by_topic(
        [m for f in support.read_mcap(recording.folder) for m in f.messages]
    )
    for topic, fields in recording.sent.items():
        expected = [support.plain(support.sent_message(TYPES[topic], f)) for f in fields]
        assert [m.fields for m in messages[topic]] == expected, topic


def test_mcap_statistics_and_metadata_agree_on_counts(recording: Recording) -> None:
    counts: dict[str, int] = {}
    for mcap_file in support.read_mcap(recording.folder):
        topics = {c.id: c.topic for c in mcap_file.channels.values()}
        for channel_id, count in mcap_file.statistics.channel_message_counts.items():
            counts[topics[channel_id]] = counts.get(topics[channel_id], 0) + count
        assert mcap_file.statistics.message_count == len(mcap_file.messages)
    assert counts == support.topic_counts(recording.folder)


def test_anyreader_decodes_every_message_as_it_was_sent(recording: Recording) -> None:
    messages = support.by_topic(support.read_anyreader(recording.folder))
    for topic, fields in recording.sent.items():
        expected = [support.plain(support.sent_message(TYPES[topic], f)) for f in fields]
        assert [m.fields for m in messages[topic]] == expected, topic
        assert {m.type for m in messages[topic]} == {TYPES[topic]}
    assert {t: len(m) for t, m in messages.items()} == support.topic_counts(recording.folder)


def test_rosbag2_reader_decodes_every_message_as_it_was_sent(recording: Recording) -> None:
    messages = support.by_topic(support.read_rosbag2(recording.folder))
    for topic, fields in recording.sent.items():
        expected = [support.plain(support.sent_message(TYPES[topic], f)) for f in fields]
        assert [m.fields for m in messages[topic]] == expected, topic
        assert [m.data for m in messages[topic]] == [support.cdr(TYPES[topic], f) for f in fields]
    assert {t: len(m) for t, m in messages.items()} == support.topic_counts(recording.folder)


def test_a_topic_that_appears_after_the_recorder_started_is_recorded(
    recording: Recording,
) -> None:
    messages = support.by_topic(support.read_anyreader(recording.folder))
    assert [m.fields["data"] for m in messages["/late_counter"]] == [-7, 0, 2147483647]
    assert "Subscribed to topic '/late_counter'" in recording.stderr


def test_rosout_and_parameter_events_are_recorded_with_all(recording: Recording) -> None:
    messages = support.by_topic(support.read_anyreader(recording.folder))
    assert "/parameter_events" in messages
    assert {m.type for m in messages["/rosout"]} == {"rcl_interfaces/msg/Log"}
    ours = [m.fields["msg"] for m in messages["/rosout"] if m.fields["name"] == "format_talker"]
    assert ours == LOG_LINES
    nodes = {m.fields["node"] for m in messages["/parameter_events"]}
    assert {"/format_talker", "/late_talker"} <= nodes


def test_file_entries_in_metadata_span_the_recorded_log_times(recording: Recording) -> None:
    info = support.metadata(recording.folder)
    for entry, mcap_file in zip(info["files"], support.read_mcap(recording.folder), strict=True):
        stamps = [m.log_time for m in mcap_file.messages]
        assert entry["message_count"] == len(stamps)
        assert entry["starting_time"]["nanoseconds_since_epoch"] == min(stamps)
        assert entry["duration"]["nanoseconds"] == max(stamps) - min(stamps)
    assert info["starting_time"]["nanoseconds_since_epoch"] == min(
        f["starting_time"]["nanoseconds_since_epoch"] for f in info["files"]
    )
