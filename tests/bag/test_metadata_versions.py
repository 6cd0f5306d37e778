"""``metadata.yaml`` of every version rosbag2 wrote (1 to 9) is read; a newer one is refused.

The layouts follow rosbag2_storage's ``yaml.hpp`` history: version 1 names the files
(``relative_file_paths``) and each topic's name, type and serialization format; 3 adds the
compression keys; 4 the ``offered_qos_profiles`` YAML text (rmw's enum numbers); 5 ``files``;
6 ``custom_data``; 7 ``type_description_hash``; 8 ``ros_distro``; 9 the profiles as a YAML
list of words. The MCAP file under each is written by the ``mcap`` library, not by rosl.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import pytest
import yaml

from rosl.bag import info as bag_info
from rosl.bag import metadata
from rosl.bag.reader import iter_bag
from rosl.cli.main import main
from tests.bag.test_info_options import BASE, NS, cdr_string, write_mcap

if TYPE_CHECKING:
    from pathlib import Path

QOS_NUMBERS = {
    "history": 3,
    "depth": 0,
    "reliability": 1,
    "durability": 1,
    "deadline": {"sec": 2147483647, "nsec": 4294967295},
    "lifespan": {"sec": 2147483647, "nsec": 4294967295},
    "liveliness": 1,
    "liveliness_lease_duration": {"sec": 2147483647, "nsec": 4294967295},
    "avoid_ros_namespace_conventions": False,
}  # fmt: skip  (as a Foxy bag holds it)
QOS_WORDS = {**QOS_NUMBERS, "history": "unknown", "reliability": "reliable",
             "durability": "transient_local", "liveliness": "automatic"}  # fmt: skip


def layout(version: int) -> dict[str, Any]:
    """A ``rosbag2_bagfile_information`` of ``version``: one topic, three messages."""
    topic: dict[str, Any] = {"name": "/said", "type": "std_msgs/msg/String",
                             "serialization_format": "cdr"}  # fmt: skip
    if 4 <= version < 9:
        topic["offered_qos_profiles"] = yaml.safe_dump([QOS_NUMBERS], sort_keys=False)
    elif version == 9:
        topic["offered_qos_profiles"] = [QOS_WORDS]
    if version >= 7:
        topic["type_description_hash"] = "RIHS01_" + "0" * 64
    found: dict[str, Any] = {
        "version": version,
        "storage_identifier": "mcap",
        "relative_file_paths": ["said.mcap"],
        "duration": {"nanoseconds": 2 * NS},
        "starting_time": {"nanoseconds_since_epoch": BASE},
        "message_count": 3,
        "topics_with_message_count": [{"topic_metadata": topic, "message_count": 3}],
    }
    if version >= 3:
        found |= {"compression_format": "", "compression_mode": ""}
    if version >= 5:
        found["files"] = [{"path": "said.mcap", "starting_time": {"nanoseconds_since_epoch": BASE},
                           "duration": {"nanoseconds": 2 * NS}, "message_count": 3}]  # fmt: skip
    if version >= 6:
        found["custom_data"] = {"made_by": "hand"}
    if version >= 8:
        found["ros_distro"] = "rolling"
    return found


def bag(folder: Path, version: int) -> Path:
    folder.mkdir()
    write_mcap(
        folder / "said.mcap",
        [("/said", "std_msgs/msg/String", BASE + k * NS, cdr_string(f"s{k}")) for k in range(3)],
    )
    text = yaml.safe_dump({"rosbag2_bagfile_information": layout(version)}, sort_keys=False)
    (folder / "metadata.yaml").write_text(text)
    return folder


@pytest.mark.parametrize("version", range(1, 10))
def test_every_metadata_version_is_read(tmp_path: Path, version: int) -> None:
    folder = bag(tmp_path / f"v{version}", version)
    assert [m.data for m in iter_bag(folder)] == [cdr_string(f"s{k}") for k in range(3)]
    found = bag_info.summary(folder)
    assert [(t["name"], t["count"]) for t in found["topics"]] == [("/said", 3)]
    assert found["start_ns"] == BASE
    if version >= 4:  # numbers (before 9) and words (9) read as the same profile
        (listed,) = metadata.read(folder)["topics_with_message_count"]
        profiles = metadata.parse_profiles(listed["topic_metadata"]["offered_qos_profiles"])
        assert [(p["reliability"], p["durability"]) for p in profiles] == [
            ("reliable", "transient_local")
        ]


@pytest.mark.parametrize(("distro", "version"), [("humble", 5), ("iron", 8), ("jazzy", 9)])
def test_a_copy_takes_the_layout_of_its_distro_and_keeps_the_profiles(
    tmp_path: Path, distro: str, version: int
) -> None:
    from rosl.bag.trim import copy

    out = tmp_path / distro
    copy(bag(tmp_path / "foxy", 4), out, ros_distro=distro)
    written = metadata.read(out)
    assert (written["version"], written["ros_distro"]) == (version, distro)
    profiles = written["topics_with_message_count"][0]["topic_metadata"]["offered_qos_profiles"]
    assert isinstance(profiles, list if version == 9 else str)
    assert [(p["reliability"], p["durability"]) for p in metadata.parse_profiles(profiles)] == [
        ("reliable", "transient_local")
    ]
    # Foxy's "infinite" durations read as rmw's infinite of today (rosbag2_storage qos.cpp)
    assert metadata.parse_profiles(profiles)[0]["deadline"] == {
        "sec": 9223372036854775807,
        "nsec": 4294967295,
    }


def test_a_newer_metadata_version_or_an_unknown_distro_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = bag(tmp_path / "v10", 9)
    text = (folder / "metadata.yaml").read_text().replace("version: 9", "version: 10", 1)
    (folder / "metadata.yaml").write_text(text)
    assert main(["bag", "info", str(folder)]) == 1
    err = capsys.readouterr().err.strip()
    assert err == (
        f"{folder / 'metadata.yaml'}: metadata version 10 is not one rosbag2 has written (1-9)"
    )
    assert main(["bag", "convert", str(bag(tmp_path / "v9", 9)), str(tmp_path / "out"),
                 "--distro", "lunar"]) == 1  # fmt: skip
    assert capsys.readouterr().err.strip() == (
        "unknown ROS distro 'lunar' (choose one of humble, iron, jazzy, kilted, rolling)"
    )
