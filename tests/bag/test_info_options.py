"""``rosl bag info -v / -t / --sort`` on bags written by other tools, and what they really hold.

The expected texts are laid out from rosbag2 Jazzy's format, not from rosl's code: ros2/rosbag2
``rosbag2_py/src/rosbag2_py/format_bag_metadata.cpp`` (labels padded to 19 columns, further
topic lines indented 19 spaces, further service lines 21, the width of "Service information: ",
"Size Contribution: " before the serialization format under -v), ``format_service_info.cpp``
(-v's "Request Count" and "Response Count": distinct client and sequence number among the
request and the response events), ``info_sorting_method.cpp`` (ascending name, type or count;
under -v a service's count is its requests plus responses), ``_info.cpp`` (each service line and
then the whole text end with a newline, so a text listing services ends with a blank line) and
``ros2bag/ros2bag/verb/info.py`` (-t prints only the topic names; -t with -v warns and -v wins).

The bags are written with the ``mcap`` library's Writer and with rosbags' rosbag2 Writer. Times
are shown in UTC (the ``utc`` fixture), as rosbag2 shows them in the local zone.
"""

from __future__ import annotations

import json
import time
from typing import TYPE_CHECKING, Any

import pytest

from rosl.cli.main import main

if TYPE_CHECKING:
    from collections.abc import Iterator
    from pathlib import Path

NS = 1_000_000_000
BASE = 1_700_000_000 * NS  # Nov 14 2023 22:13:20 UTC
PAD = " " * 19
SERVICE_PAD = " " * 21


def cdr_string(text: str) -> bytes:
    """A std_msgs/msg/String in little-endian CDR: header, length, the text and its NUL."""
    raw = text.encode() + b"\x00"
    return b"\x00\x01\x00\x00" + len(raw).to_bytes(4, "little") + raw


def cdr_int32(value: int) -> bytes:
    return b"\x00\x01\x00\x00" + value.to_bytes(4, "little", signed=True)


def service_event(service_type: str, event_type: int, gid: int, seq: int) -> bytes:
    """A ``<service>_Event`` (no request or response attached) in CDR."""
    from rosl.idl import registry

    event = registry.get_message_class(f"{service_type}_Event")
    info = registry.get_message_class("service_msgs/msg/ServiceEventInfo")
    stamp = registry.get_message_class("builtin_interfaces/msg/Time")
    return registry.store().serialize(
        event(info=info(event_type=event_type, stamp=stamp(sec=1, nanosec=0),
                        client_gid=[gid] * 16, sequence_number=seq))
    )  # fmt: skip


def write_mcap(
    path: Path, messages: list[tuple[str, str, int, bytes]], encodings: dict[str, str] | None = None
) -> Path:
    """One MCAP file written by the mcap library: (topic, type, log time, data) in order.

    ``encodings`` gives a topic a message encoding other than cdr.
    """
    from mcap.writer import Writer

    with path.open("wb") as handle:
        writer = Writer(handle, enable_crcs=False)
        writer.start(profile="ros2", library="outside writer")
        channels: dict[str, int] = {}
        for topic, type_name, log_time, data in messages:
            if topic not in channels:
                encoding = (encodings or {}).get(topic, "cdr")
                schema = writer.register_schema(
                    type_name, "ros2msg" if encoding == "cdr" else "jsonschema", b"# outside\n"
                )
                channels[topic] = writer.register_channel(topic, encoding, schema)
            writer.add_message(channels[topic], log_time, data, log_time)
        writer.finish()
    return path


def start_recorded_late(path: Path, start_ns: int) -> None:
    """Make the Statistics and chunk index records say the messages start at ``start_ns``.

    An older writer kept its running minimum with 0 meaning "unset", so a message logged at
    time 0 did not count: its summary starts at the next message.
    """
    data = bytearray(path.read_bytes())
    footer = len(data) - 8 - 29  # the footer record before the closing magic
    assert data[footer] == 0x02
    pos = int.from_bytes(data[footer + 9 : footer + 17], "little")  # the summary's start
    patched = set()
    while pos < footer:
        opcode, length = data[pos], int.from_bytes(data[pos + 1 : pos + 9], "little")
        field = {0x0B: pos + 9 + 26, 0x08: pos + 9}.get(opcode)  # message_start_time
        if field is not None:
            data[field : field + 8] = start_ns.to_bytes(8, "little")
            patched.add(opcode)
        pos += 9 + length
    assert patched == {0x0B, 0x08}, patched
    path.write_bytes(bytes(data))


def zero_start_bag(folder: Path) -> Path:
    """/zero holds messages at log times 0, 1 s and 2 s; its summary says it starts at 1 s."""
    folder.mkdir()
    path = write_mcap(
        folder / "zero.mcap",
        [("/zero", "std_msgs/msg/String", k * NS, cdr_string(f"z{k}")) for k in range(3)],
    )
    start_recorded_late(path, NS)
    return path


def json_bag(folder: Path) -> Path:
    """A bag with one cdr topic and one json-encoded channel."""
    folder.mkdir()
    write_mcap(
        folder / "mixed.mcap",
        [("/ok", "std_msgs/msg/String", BASE, cdr_string("fine")),
         ("/data", "demo/Data", BASE + 1, b'{"x": 1}')],
        encodings={"/data": "json"},
    )  # fmt: skip
    return folder


ADD, TRIGGER = "example_interfaces/srv/AddTwoInts", "std_srvs/srv/Trigger"


@pytest.fixture(scope="module")
def outside(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Any]:
    """A single MCAP file by the mcap Writer: three topics (one named relatively) and two
    services; /add shows 4 events of 1 call (2 = 1 request + 1 response), /trig 3 events of
    2 requests and 1 response (3)."""
    add = "/add/_service_event"
    trig = "/trig/_service_event"
    plan = [
        (0.0, "/a_text", "std_msgs/msg/String", cdr_string("m0")),
        (0.1, "/b_number", "std_msgs/msg/Int32", cdr_int32(1)),
        (0.2, "/b_number", "std_msgs/msg/Int32", cdr_int32(2)),
        (0.3, "/b_number", "std_msgs/msg/Int32", cdr_int32(3)),
        (0.4, "/b_number", "std_msgs/msg/Int32", cdr_int32(4)),
        (0.5, "/a_text", "std_msgs/msg/String", cdr_string("m1")),
        (0.6, "/b_number", "std_msgs/msg/Int32", cdr_int32(5)),
        (0.7, "AAA", "std_msgs/msg/String", cdr_string("hello")),
        (0.8, add, f"{ADD}_Event", service_event(ADD, 0, 7, 1)),  # REQUEST_SENT
        (0.9, add, f"{ADD}_Event", service_event(ADD, 1, 7, 1)),  # REQUEST_RECEIVED, same call
        (1.0, add, f"{ADD}_Event", service_event(ADD, 2, 7, 1)),  # RESPONSE_SENT
        (1.1, add, f"{ADD}_Event", service_event(ADD, 3, 7, 1)),  # RESPONSE_RECEIVED
        (1.2, trig, f"{TRIGGER}_Event", service_event(TRIGGER, 0, 9, 1)),
        (1.25, trig, f"{TRIGGER}_Event", service_event(TRIGGER, 0, 9, 2)),
        (1.3, trig, f"{TRIGGER}_Event", service_event(TRIGGER, 2, 9, 1)),
    ]
    path = tmp_path_factory.mktemp("outside") / "outside.mcap"
    write_mcap(path, [(t, ty, BASE + round(at * NS), data) for at, t, ty, data in plan])
    sizes: dict[str, int] = {}
    for _, topic, _, data in plan:
        sizes[topic] = sizes.get(topic, 0) + len(data)
    return {"path": path, "sizes": sizes}


@pytest.fixture(autouse=True)
def utc(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    monkeypatch.setenv("TZ", "UTC")
    time.tzset()
    yield
    monkeypatch.undo()
    time.tzset()


def info(capsys: pytest.CaptureFixture[str], *args: object) -> tuple[int, str, str]:
    code = main(["bag", "info", *[str(a) for a in args]])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def size_text(size: int) -> str:
    """rosbag2's format_file_size: bytes as they are, larger sizes in binary units, 1 decimal."""
    value, unit = float(size), 0
    while value >= 1024 and unit < 4:
        value, unit = value / 1024, unit + 1
    return f"{size} B" if unit == 0 else f"{value:.1f} {['B', 'KiB', 'MiB', 'GiB', 'TiB'][unit]}"


def header(path: Path, distro: str = "unknown") -> list[str]:
    return [
        "",
        "Files:             outside.mcap",
        f"Bag size:          {size_text(path.stat().st_size)}",
        "Storage id:        mcap",
        f"ROS Distro:        {distro}",
        "Duration:          1.300000000s",
        "Start:             Nov 14 2023 22:13:20.000000000 (1700000000.000000000)",
        "End:               Nov 14 2023 22:13:21.300000000 (1700000001.300000000)",
        "Messages:          8",
    ]


def test_info_of_another_tools_bag_prints_rosbag2s_layout(capsys, outside):
    code, out, err = info(capsys, outside["path"])
    assert (code, err) == (0, "")
    assert out == "\n".join([
        *header(outside["path"]),
        "Topic information: Topic: /a_text | Type: std_msgs/msg/String | Count: 2 | "
        "Serialization Format: cdr",
        PAD + "Topic: /b_number | Type: std_msgs/msg/Int32 | Count: 5 | Serialization Format: cdr",
        PAD + "Topic: AAA | Type: std_msgs/msg/String | Count: 1 | Serialization Format: cdr",
        "Service:           2",
        "Service information: Service: /add | Type: example_interfaces/srv/AddTwoInts | "
        "Event Count: 4 | Serialization Format: cdr",
        SERVICE_PAD + "Service: /trig | Type: std_srvs/srv/Trigger | Event Count: 3 | "
        "Serialization Format: cdr",
        "",
    ]) + "\n"  # fmt: skip


def test_info_verbose_adds_size_contributions_and_request_and_response_counts(capsys, outside):
    size = {topic: f"{count} B" for topic, count in outside["sizes"].items()}
    code, out, _ = info(capsys, "-v", outside["path"])
    assert code == 0
    assert out == "\n".join([
        *header(outside["path"]),
        "Topic information: Topic: /a_text | Type: std_msgs/msg/String | Count: 2 | "
        "Size Contribution: 22 B | Serialization Format: cdr",  # 2 x (4 + 4 + 3)
        PAD + "Topic: /b_number | Type: std_msgs/msg/Int32 | Count: 5 | "
        "Size Contribution: 40 B | Serialization Format: cdr",
        PAD + "Topic: AAA | Type: std_msgs/msg/String | Count: 1 | "
        "Size Contribution: 14 B | Serialization Format: cdr",
        "Service:           2",
        "Service information: Service: /add | Type: example_interfaces/srv/AddTwoInts | "
        "Request Count: 1 | Response Count: 1 | "
        f"Size Contribution: {size['/add/_service_event']} | Serialization Format: cdr",
        SERVICE_PAD + "Service: /trig | Type: std_srvs/srv/Trigger | "
        "Request Count: 2 | Response Count: 1 | "
        f"Size Contribution: {size['/trig/_service_event']} | Serialization Format: cdr",
        "",
    ]) + "\n"  # fmt: skip


@pytest.mark.parametrize(
    ("sort", "topics", "services", "services_verbose"),
    [
        ("name", ["/a_text", "/b_number", "AAA"], ["/add", "/trig"], ["/add", "/trig"]),
        ("type", ["/b_number", "/a_text", "AAA"], ["/add", "/trig"], ["/add", "/trig"]),
        # counts: topics 5, 2, 1; events /add 4, /trig 3; calls /add 1 + 1, /trig 2 + 1
        ("count", ["AAA", "/a_text", "/b_number"], ["/trig", "/add"], ["/add", "/trig"]),
        ("COUNT", ["AAA", "/a_text", "/b_number"], ["/trig", "/add"], ["/add", "/trig"]),
    ],
)
def test_info_sort_orders_topics_and_services_as_rosbag2(
    capsys, outside, sort, topics, services, services_verbose
):
    code, out, _ = info(capsys, "-t", "--sort", sort, outside["path"])
    assert code == 0
    assert out.splitlines() == topics  # -t: the names only, no service events
    for flags, expected in (([], services), (["-v"], services_verbose)):
        code, out, _ = info(capsys, *flags, "--sort", sort, outside["path"])
        shown = [line.split(" | ")[0].split("Service: ")[-1] for line in out.splitlines()
                 if "Service: /" in line]  # fmt: skip
        assert (code, shown) == (0, expected), flags
        listed = [line.split(" | ")[0].split("Topic: ")[-1] for line in out.splitlines()
                  if "Topic: " in line]  # fmt: skip
        assert listed == topics


def test_info_topic_name_and_verbose_together_warn_and_print_the_verbose_text(capsys, outside):
    _, verbose, _ = info(capsys, "-v", outside["path"])
    code, out, err = info(capsys, "-t", "-v", outside["path"])
    assert code == 0
    assert out == verbose
    assert err.strip() == (
        "Warning! You have set both the '-t' and '-v' parameters. "
        "The '-t' parameter will be ignored."
    )


def test_info_json_verbose_holds_sizes_and_calls(capsys, outside):
    code, out, _ = info(capsys, "--json", "-v", "--sort", "count", outside["path"])
    assert code == 0
    data = json.loads(out)
    assert [(t["name"], t["count"], t["size"]) for t in data["topics"]] == [
        ("AAA", 1, 14), ("/a_text", 2, 22), ("/b_number", 5, 40)
    ]  # fmt: skip
    assert [(s["name"], s["request_count"], s["response_count"]) for s in data["services"]] == [
        ("/add", 1, 1), ("/trig", 2, 1)
    ]  # fmt: skip
    assert (data["start_ns"], data["end_ns"], data["messages"]) == (BASE, BASE + 13 * NS // 10, 8)


def test_info_of_a_bag_written_by_rosbags_reads_its_metadata_and_its_messages(capsys, tmp_path):
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    string = store.types["std_msgs/msg/String"]
    folder = tmp_path / "by_rosbags"
    with Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection("AAA", "std_msgs/msg/String", typestore=store)
        for k in range(3):
            data = store.serialize_cdr(string(data=f"r{k}"), "std_msgs/msg/String")
            writer.write(connection, BASE + k * NS // 4, data)
    (mcap,) = folder.glob("*.mcap")
    code, out, err = info(capsys, folder)
    assert (code, err) == (0, "")
    assert out == "\n".join([
        "",
        f"Files:             {mcap.name}",
        f"Bag size:          {size_text(mcap.stat().st_size)}",
        "Storage id:        mcap",
        "ROS Distro:        rosbags",  # as its metadata.yaml names it
        "Duration:          0.500000000s",
        "Start:             Nov 14 2023 22:13:20.000000000 (1700000000.000000000)",
        "End:               Nov 14 2023 22:13:20.500000000 (1700000000.500000000)",
        "Messages:          3",
        "Topic information: Topic: AAA | Type: std_msgs/msg/String | Count: 3 | "
        "Serialization Format: cdr",
        "Service:           0",
        "Service information: ",
    ]) + "\n"  # fmt: skip


def test_info_takes_the_start_from_the_messages_not_from_the_statistics(capsys, tmp_path):
    from mcap.reader import make_reader

    path = zero_start_bag(tmp_path / "zero")
    with path.open("rb") as handle:
        summary = make_reader(handle).get_summary()
    assert summary is not None
    assert summary.statistics.message_start_time == NS  # what the summary claims
    code, out, _ = info(capsys, path)
    assert code == 0
    lines = out.splitlines()
    assert "Duration:          2.000000000s" in lines
    assert "Start:             Jan  1 1970 00:00:00.000000000 (0.000000000)" in lines
    assert "End:               Jan  1 1970 00:00:02.000000000 (2.000000000)" in lines
    assert "Messages:          3" in lines


def test_info_reads_the_chunks_of_a_file_without_message_indexes(capsys, tmp_path):
    from mcap.writer import IndexType, Writer

    path = tmp_path / "no_message_index.mcap"
    with path.open("wb") as handle:
        writer = Writer(handle, index_types=IndexType.CHUNK, chunk_size=64, enable_crcs=False)
        writer.start(profile="ros2", library="outside writer")
        schema = writer.register_schema("std_msgs/msg/Int32", "ros2msg", b"int32 data\n")
        channel = writer.register_channel("/n", "cdr", schema)
        for k in range(6):  # several chunks
            writer.add_message(channel, k * NS, cdr_int32(k), k * NS)
        writer.finish()
    start_recorded_late(path, NS)
    code, out, _ = info(capsys, "--json", path)
    data = json.loads(out)
    assert (code, data["start_ns"], data["end_ns"], data["messages"]) == (0, 0, 5 * NS, 6)


def test_info_refuses_a_channel_that_is_not_cdr_in_one_line(capsys, tmp_path):
    folder = json_bag(tmp_path / "mixed")
    for flags in ([], ["--json"], ["-v"]):
        code, out, err = info(capsys, *flags, folder)
        assert (code, out) == (1, "")
        assert err.splitlines() == ["Could not find converter for format json (topic /data)"]


def test_convert_refuses_a_channel_that_is_not_cdr_in_one_line(capsys, tmp_path):
    folder = json_bag(tmp_path / "mixed")
    code = main(["bag", "convert", str(folder), str(tmp_path / "converted")])
    captured = capsys.readouterr()
    assert code == 1
    assert captured.err.splitlines() == ["Could not find converter for format json (topic /data)"]
    assert not (tmp_path / "converted").exists()


def test_info_with_an_unknown_sort_key_says_so_in_one_line(capsys, outside):
    code, out, err = info(capsys, "--sort", "size", outside["path"])
    assert (code, out) == (1, "")
    assert err.splitlines() == ["--sort 'size' is not one of name, type, count"]
