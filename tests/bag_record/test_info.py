"""``rosl bag info DIR|FILE [--json]``: ROS 2's layout, with the counts of the bag on disk.

The bag is the session's service recording (topics /numbers and /words, /parameter_events,
and /add_two_ints service events). Expected values are computed from the files with
``mcap``'s reader and from metadata.yaml, and laid out as ``ros2 bag info`` does: a leading
blank line, labels padded to 19 columns, continuation lines indented 19 spaces, binary sizes,
local-time dates with nine-digit nanoseconds; further service lines are indented 21 spaces.
"""

from __future__ import annotations

import datetime
import json
import shutil
from typing import TYPE_CHECKING

from tests.bag_record import support
from tests.bag_record.conftest import NUMBERS

if TYPE_CHECKING:
    from pathlib import Path

    from tests.bag_record.conftest import ServiceBag

PAD = " " * 19


def size_text(size: int) -> str:
    value, unit = float(size), 0
    units = ["B", "KiB", "MiB", "GiB", "TiB"]
    while value >= 1024 and unit < 4:
        value /= 1024
        unit += 1
    return f"{size} B" if unit == 0 else f"{value:.1f} {units[unit]}"


def stamp_text(ns: int) -> str:
    sec, nanos = divmod(ns, 1_000_000_000)
    moment = datetime.datetime.fromtimestamp(sec)
    return f"{moment.strftime('%b %e %Y %H:%M:%S')}.{nanos:09d} ({sec}.{nanos:09d})"


def expected_info(
    folder: Path, files: list[Path], distro: str, *, listed: bool = True
) -> list[str]:
    """``ros2 bag info``'s lines for ``files``: the topics that hold messages and, when
    ``listed`` (the folder is read, with its metadata.yaml), every other topic metadata.yaml
    lists, with Count: 0 (rosbag2's format_bag_meta_data prints each topic of the metadata).
    """
    messages = [m for path in files for m in support.read_mcap_file(path).messages]
    counts: dict[str, int] = {}
    types: dict[str, str] = {}
    for message in messages:
        counts[message.topic] = counts.get(message.topic, 0) + 1
        types[message.topic] = message.type
    if listed:
        for entry in support.metadata(folder)["topics_with_message_count"]:
            counts.setdefault(entry["topic_metadata"]["name"], 0)
            types.setdefault(entry["topic_metadata"]["name"], entry["topic_metadata"]["type"])
    stamps = [m.log_time for m in messages]
    start, end = min(stamps), max(stamps)
    seconds, nanos = divmod(end - start, 1_000_000_000)
    topics = sorted(t for t in counts if not t.endswith("/_service_event"))
    services = sorted(t for t in counts if t.endswith("/_service_event"))
    topic_lines = [
        f"Topic: {t} | Type: {types[t]} | Count: {counts[t]} | Serialization Format: cdr"
        for t in topics
    ]
    service_lines = [
        f"Service: {t.removesuffix('/_service_event')} | "
        f"Type: {types[t].removesuffix('_Event')} | Event Count: {counts[t]} | "
        "Serialization Format: cdr"
        for t in services
    ]
    lines = [
        "",
        f"{'Files:':<19}{files[0].name}",
        *[PAD + p.name for p in files[1:]],
        f"{'Bag size:':<19}{size_text(sum(p.stat().st_size for p in files))}",
        f"{'Storage id:':<19}mcap",
        f"{'ROS Distro:':<19}{distro}",
        f"{'Duration:':<19}{seconds}.{nanos:09d}s",
        f"{'Start:':<19}{stamp_text(start)}",
        f"{'End:':<19}{stamp_text(end)}",
        f"{'Messages:':<19}{sum(counts[t] for t in topics)}",
        f"{'Topic information:':<19}{topic_lines[0]}",
        *[PAD + line for line in topic_lines[1:]],
        f"{'Service:':<19}{len(services)}",
        "Service information: " + service_lines[0],
        # rosbag2 (rosbag2_py/src/rosbag2_py/format_bag_metadata.cpp) indents further service
        # lines by 21, the width of "Service information: ", and ends each service line and
        # then the whole text with a newline: a text that lists services ends with a blank line
        *[" " * 21 + line for line in service_lines[1:]],
        "",
    ]
    return lines


def test_info_of_a_folder_prints_ros2s_layout_with_the_bags_numbers(
    service_bag: ServiceBag,
) -> None:
    result = support.rosl_run("bag", "info", str(service_bag.folder))
    assert result.returncode == 0, result.stderr
    files = support.bag_files(service_bag.folder)
    distro = support.metadata(service_bag.folder)["ros_distro"]
    assert result.stdout.splitlines() == expected_info(service_bag.folder, files, distro)


def test_info_messages_line_leaves_out_service_events(service_bag: ServiceBag) -> None:
    lines = support.rosl_run("bag", "info", str(service_bag.folder)).stdout.splitlines()
    counts = support.topic_counts(service_bag.folder)
    topics = sum(n for t, n in counts.items() if not t.endswith("/_service_event"))
    assert topics == support.metadata(service_bag.folder)["message_count"] - 4
    assert f"{'Messages:':<19}{topics}" in lines
    assert (
        "Service information: Service: /add_two_ints | Type: example_interfaces/srv/AddTwoInts"
        " | Event Count: 4 | Serialization Format: cdr"
    ) in lines


def test_info_of_one_mcap_file_reads_the_file_itself(service_bag: ServiceBag) -> None:
    (path,) = support.bag_files(service_bag.folder)
    result = support.rosl_run("bag", "info", str(path))
    assert result.returncode == 0, result.stderr
    got = result.stdout.splitlines()
    expected = expected_info(service_bag.folder, [path], "", listed=False)
    # without the folder's metadata.yaml there is no distro to show; everything else is the same
    assert [line for line in got if not line.startswith("ROS Distro:")] == [
        line for line in expected if not line.startswith("ROS Distro:")
    ]


def test_info_json_parses_with_the_same_numbers(service_bag: ServiceBag) -> None:
    result = support.rosl_run("bag", "info", "--json", str(service_bag.folder))
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    files = support.bag_files(service_bag.folder)
    messages = [m for path in files for m in support.read_mcap_file(path).messages]
    stamps = [m.log_time for m in messages]
    counts = support.topic_counts(service_bag.folder)  # every topic listed, Count: 0 too
    assert data["files"] == [p.name for p in files]
    assert data["bag_size"] == sum(p.stat().st_size for p in files)
    assert data["storage_id"] == "mcap"
    assert (data["start_ns"], data["end_ns"]) == (min(stamps), max(stamps))
    assert data["duration_ns"] == max(stamps) - min(stamps)
    assert {t["name"]: t["count"] for t in data["topics"]} == {
        t: n for t, n in counts.items() if not t.endswith("/_service_event")
    }
    assert all(t["serialization_format"] == "cdr" for t in data["topics"])
    assert data["messages"] == sum(t["count"] for t in data["topics"])
    # every service metadata.yaml lists (the nodes' parameter services with no events too)
    services = {s["name"]: (s["type"], s["event_count"]) for s in data["services"]}
    assert services == {
        t.removesuffix("/_service_event"): (services[t.removesuffix("/_service_event")][0], n)
        for t, n in counts.items()
        if t.endswith("/_service_event")
    }
    assert services["/add_two_ints"] == ("example_interfaces/srv/AddTwoInts", 4)


def test_info_lists_every_topic_of_metadata_even_without_messages(
    service_bag: ServiceBag,
) -> None:
    """ros2 bag info prints each topic metadata.yaml lists, with Count: 0 when none came."""
    counts = support.topic_counts(service_bag.folder)
    silent = sorted(t for t, n in counts.items() if n == 0 and not t.endswith("/_service_event"))
    assert silent, "the recording has no subscribed-but-silent topic to check (/rosout)"
    text = support.rosl_run("bag", "info", str(service_bag.folder)).stdout
    for topic in silent:
        assert f"Topic: {topic} | " in text, f"{topic} (Count: 0 in metadata.yaml) is missing"
    services = sum(1 for t in counts if t.endswith("/_service_event"))
    assert f"{'Service:':<19}{services}" in text.splitlines()


def test_info_without_a_known_distro_says_unknown_as_ros2_does(service_bag: ServiceBag) -> None:
    """rosbag2's format_bag_meta_data prints "unknown" when the bag names no ROS distro."""
    (path,) = support.bag_files(service_bag.folder)
    lines = support.rosl_run("bag", "info", str(path)).stdout.splitlines()
    distro = [line for line in lines if line.startswith("ROS Distro:")]
    assert distro == [f"{'ROS Distro:':<19}unknown"], distro


def footer_summary_start(path: Path) -> int:
    """The summary section's offset, from the footer record before the closing magic."""
    data = path.read_bytes()
    footer = data[-8 - 29 :]  # opcode, length, summary_start, summary_offset_start, crc
    assert footer[0] == 0x02, "not a footer record"
    return int.from_bytes(footer[9:17], "little")


def test_info_of_a_finished_file_answers_from_its_summary_without_reading_chunks(
    service_bag: ServiceBag, tmp_path: Path
) -> None:
    """Every chunk of a copy is overwritten with garbage; its summary is left whole. ``info``
    reads the summary (statistics, channels, schemas) only, so it prints what it printed for
    the original file."""
    from mcap.reader import make_reader

    (original,) = support.bag_files(service_bag.folder)
    path = tmp_path / original.name
    shutil.copy(original, path)
    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None
    assert summary.chunk_indexes
    with path.open("r+b") as handle:
        for chunk in summary.chunk_indexes:
            handle.seek(chunk.chunk_start_offset + 9 + 40)  # past opcode, length, header fields
            handle.write(b"\xff" * (chunk.chunk_length - 9 - 40))
    assert path.stat().st_size == original.stat().st_size
    expected = support.rosl_run("bag", "info", str(original))
    assert expected.returncode == 0, expected.stderr
    result = support.rosl_run("bag", "info", str(path))
    assert result.returncode == 0, result.stderr
    assert result.stdout == expected.stdout
    assert "Topic: /numbers | Type: std_msgs/msg/Int32 | Count: 5 |" in result.stdout


def test_info_of_an_unfinished_file_scans_it_to_the_same_numbers(
    service_bag: ServiceBag, tmp_path: Path
) -> None:
    """A copy cut where its summary begins holds every message but no summary: info reads
    it record by record and prints the same table, plus the note that it is unfinished."""
    (original,) = support.bag_files(service_bag.folder)
    path = tmp_path / original.name
    shutil.copy(original, path)
    with path.open("r+b") as handle:
        handle.truncate(footer_summary_start(path))
    finished = json.loads(support.rosl_run("bag", "info", "--json", str(original)).stdout)
    result = support.rosl_run("bag", "info", "--json", str(path))
    assert result.returncode == 0, result.stderr
    scanned = json.loads(result.stdout)
    assert scanned.pop("unfinished") == [path.name]
    assert finished.pop("unfinished") == []
    del scanned["bag_size"], finished["bag_size"]
    assert scanned == finished


def test_info_verbose_shows_the_recorded_calls_and_each_topics_bytes(
    service_bag: ServiceBag,
) -> None:
    """-v (rosbag2 Jazzy): each topic's and service's size contribution (the sum of its
    serialized messages) and, per service, the requests and responses its events show."""
    from mcap.reader import make_reader

    result = support.rosl_run("bag", "info", "-v", str(service_bag.folder))
    assert result.returncode == 0, result.stderr
    sizes: dict[str, int] = {}
    for path in support.bag_files(service_bag.folder):
        with path.open("rb") as handle:
            for _, channel, message in make_reader(handle).iter_messages():
                sizes[channel.topic] = sizes.get(channel.topic, 0) + len(message.data)
    calls = len(service_bag.calls)
    lines = result.stdout.splitlines()
    entries = [line.split(": ", 1)[1] if line.startswith(("Topic information", "Service inf"))
               else line.strip() for line in lines]  # fmt: skip
    assert (
        "Service: /add_two_ints | Type: example_interfaces/srv/AddTwoInts | "
        f"Request Count: {calls} | Response Count: {calls} | "
        f"Size Contribution: {size_text(sizes['/add_two_ints/_service_event'])} | "
        "Serialization Format: cdr"
    ) in entries
    assert (
        f"Topic: /numbers | Type: std_msgs/msg/Int32 | Count: {len(NUMBERS)} | "
        f"Size Contribution: {size_text(sizes['/numbers'])} | Serialization Format: cdr"
    ) in entries
